#!/usr/bin/env python3
"""Scores injection-recovery (bench/injection_recovery.sh): per injected
session, the diagnosis against the same session without injection.

Usage: injection_score.py OUT_DIR SESSION... --injections "name|effect:k=v,..."...
Writes OUT_DIR/scores.json and OUT_DIR/table.md and prints the table.

Per injection:
  named    the injected effect is in verdict.effects
  leads    it is verdict.effect (a named verdict led by it)
  first    it is the first of verdict.effects (also when the verdict is
           `unexplained`: the effect that closes most of the gap)
  none     verdict.effect is `none`
  invents  verdict.effects holds an effect neither injected nor in the
           session's own verdict (without injection)
  size     the candidate's fitted size minus the same candidate's fit on
           the session without injection, against the injected size:
           within 25 % (gt_offset: the vector (dx, dy), within 25 % of its
           length). Scored ("the 32") for the injections with one size:
           time_offset, gt_offset, turn_scrub, scale_error. For the others
           the ratio is printed (for random effects the fitted sizes are
           combined as sqrt(fit^2 - base^2); bumps as rate sigma^2, the
           variance they add per metre, fit minus base).
  n/a      the injection changed no ground-truth sample by more than 1 um or
           1 urad (the session has no event it acts on, e.g. a swivel castor
           without spot turns or reversals): not scored.
"""
import argparse
import json
import math
import os
import sys

SIZED = {"time_offset": ["tau"], "gt_offset": ["dx", "dy"], "turn_scrub": ["k"], "scale_error": ["s"]}
RANDOM = {"run_time_offset": "tau_sd", "standstill_motion": "sigma_theta",
          "motion_noise_floor": "sigma"}
OTHER = {"direction_asymmetry": "a", "castor_kick": "kappa", "parameter_drift": "r", "stop_slide": "d",
         "castor_swivel": "kappa"}
CORE = ["time_offset_p80", "time_offset_m60", "run_time_offset", "gt_offset_a", "gt_offset_b", "turn_scrub_3",
        "turn_scrub_5", "bump_outliers", "scale_error_p", "scale_error_m"]


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def params_of(effect_text):
    name, _, rest = effect_text.partition(":")
    p = {}
    for kv in filter(None, rest.split(",")):
        k, v = kv.split("=")
        p[k] = float(v)
    return name, p


def candidate(diag, effect):
    for c in diag.get("candidates", []):
        if c.get("effect") == effect:
            return c.get("params", {})
    return None


def size_score(effect, injected, diag, base):
    """(ratio text, within 25 % or None when not scored)."""
    c, c0 = candidate(diag, effect), candidate(base, effect)
    if c is None:
        return "not fitted", (False if effect in SIZED else None)
    c0 = c0 or {}
    if effect == "gt_offset":
        dx = c.get("dx", math.nan) - c0.get("dx", 0.0)
        dy = c.get("dy", math.nan) - c0.get("dy", 0.0)
        err = math.hypot(dx - injected["dx"], dy - injected["dy"])
        ok = err <= 0.25 * math.hypot(injected["dx"], injected["dy"])
        return f"({dx * 1e3:+.1f}, {dy * 1e3:+.1f}) mm", ok
    if effect in SIZED:
        key = SIZED[effect][0]
        got = c.get(key, math.nan) - c0.get(key, 0.0)
        ok = abs(got - injected[key]) <= 0.25 * abs(injected[key])
        return f"{got / injected[key]:.2f}x", ok
    if effect == "bump_outliers":
        var = lambda p: p.get("rate", math.nan) * p.get("sigma", math.nan) ** 2
        got = var(c) - (var(c0) if c0 else 0.0)
        return f"{got / var(injected):.2f}x", None
    if effect in RANDOM:
        key = RANDOM[effect]
        f1, f0 = c.get(key, math.nan), c0.get(key, 0.0)
        got = math.sqrt(max(f1 * f1 - f0 * f0, 0.0)) if math.isfinite(f1) else math.nan
        return f"{got / injected[key]:.2f}x", None
    key = OTHER.get(effect)
    if key is None or key not in injected:
        return "-", None
    got = c.get(key, math.nan) - c0.get(key, 0.0)
    return f"{got / injected[key]:.2f}x", None


def footprint(inject_file):
    pos = head = 0.0
    if not os.path.exists(inject_file):
        return pos, head
    with open(inject_file) as f:
        for line in f:
            if line.strip():
                j = json.loads(line)
                pos = max(pos, j["max_position_change_m"])
                head = max(head, j["max_heading_change_rad"])
    return pos, head


def score(out, sessions, injections):
    rows = []
    for s in sessions:
        base = load(os.path.join(out, s, "base", "diagnosis.json"))
        if base is None:
            print(f"{s}: no diagnosis of the session without injection", file=sys.stderr)
            continue
        bv = base["verdict"]
        base_named = set(bv.get("effects", []))
        # In the verdict's order: its first is the effect the agreement
        # check compares (it was sorted by name before session 18, so that
        # check read the alphabetically first effect).
        rows.append(dict(session=s, injection="base", effect="-", verdict=bv["effect"],
                         effects=list(bv.get("effects", []))))
        for line in injections:
            name, effect_text = line.split("|", 1)
            effect, injected = params_of(effect_text.split()[0])
            d = os.path.join(out, s, name)
            diag = load(os.path.join(d, "diagnosis.json"))
            pos, head = footprint(os.path.join(d, "inject.jsonl"))
            r = dict(session=s, injection=name, effect=effect, footprint_mm=pos * 1e3, footprint_mrad=head * 1e3,
                     core=name in CORE)
            if diag is None:
                r.update(verdict="(failed)", effects=[], named=False, leads=False, first=False, none=False, invents=[],
                         size="-", size_ok=None, applicable=True)
                rows.append(r)
                continue
            v = diag["verdict"]
            named = list(v.get("effects", []))
            size_text, size_ok = size_score(effect, injected, diag, base)
            r.update(verdict=v["effect"], effects=named, named=effect in named, leads=v["effect"] == effect,
                     first=bool(named) and named[0] == effect,
                     none=v["effect"] == "none", invents=[e for e in named if e != effect and e not in base_named],
                     size=size_text, size_ok=size_ok, applicable=pos > 1e-6 or head > 1e-6)
            rows.append(r)
    return rows


def totals(rows, pick):
    sel = [r for r in rows if r["injection"] != "base" and r["applicable"] and pick(r)]
    sized = [r for r in sel if r["size_ok"] is not None]
    return dict(n=len(sel), named=sum(r["named"] for r in sel), leads=sum(r["leads"] for r in sel),
                first=sum(r["first"] for r in sel),
                none=sum(r["none"] for r in sel), invents=sum(bool(r["invents"]) for r in sel),
                sized=len(sized), size_ok=sum(bool(r["size_ok"]) for r in sized))


def table(rows):
    L = ["| session | injection | footprint | verdict | named effects | named | leads | first | size | invents |",
         "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["injection"] == "base":
            L.append(f"| {r['session']} | (none) | - | {r['verdict']} | {', '.join(r['effects']) or '-'} | | | | | |")
            continue
        if not r["applicable"]:
            L.append(f"| {r['session']} | {r['injection']} | 0 (n/a) | | | | | | | |")
            continue
        ok = {True: "yes", False: "**no**", None: ""}
        size = r["size"] + (" ok" if r["size_ok"] else " **off**" if r["size_ok"] is False else "")
        L.append(f"| {r['session']} | {r['injection']} | {r['footprint_mm']:.2f} mm, {r['footprint_mrad']:.1f} mrad | "
                 f"{'**none**' if r['none'] else r['verdict']} | {', '.join(r['effects']) or '-'} | "
                 f"{ok[r['named']]} | {ok[r['leads']]} | {ok[r['first']]} | {size} | {', '.join(r['invents']) or ''} |")
    return "\n".join(L)


def summary_line(label, t):
    return (f"{label}: named {t['named']}/{t['n']}, leads {t['leads']}/{t['n']}, first named {t['first']}/{t['n']}, "
            f"size within 25 % "
            f"{t['size_ok']}/{t['sized']}, none {t['none']}/{t['n']}, inventions {t['invents']}/{t['n']}")


def agreement(bases):
    """The issue's check on the sessions without injection: how many lead
    with the same named effect (the first of verdict.effects)."""
    firsts = [r["effects"][0] if r["effects"] else r["verdict"] for r in bases]
    if not firsts:
        return ""
    common = max(set(firsts), key=firsts.count)
    return (f"first named effect without injection: {', '.join(firsts)}; "
            f"{firsts.count(common)} of {len(firsts)} agree ({common})")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("sessions", nargs="+")
    ap.add_argument("--injections", required=True)
    a = ap.parse_args()
    injections = [l for l in a.injections.splitlines() if l.strip()]
    rows = score(a.out, a.sessions, injections)
    core = totals(rows, lambda r: r["core"])
    other = totals(rows, lambda r: not r["core"])
    bases = [r for r in rows if r["injection"] == "base"]
    lines = [table(rows), "",
             summary_line("the issue's ten injections", core),
             summary_line("the other contract effects", other),
             "sessions without injection: " + "; ".join(f"{r['session']} {r['verdict']} ({', '.join(r['effects'])})"
                                                       for r in bases),
             agreement(bases)]
    text = "\n".join(lines)
    with open(os.path.join(a.out, "table.md"), "w") as f:
        f.write(text + "\n")
    with open(os.path.join(a.out, "scores.json"), "w") as f:
        json.dump(dict(rows=rows, core=core, other=other), f, indent=1)
    print(text)


if __name__ == "__main__":
    main()
