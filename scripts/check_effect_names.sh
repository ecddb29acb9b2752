#!/usr/bin/env bash
# One file per effect (issue 28 item 4): no library file outside lib/effects/
# names an effect. Fails on every line of lib/ (outside lib/effects/) that,
# comments stripped, holds a registered effect's name (the `.name = "..."`
# of lib/effects/*.cpp) as a word, a member access to one of their
# parameters' fields in Effects (`.scale_s`, `&Effects::scale_s`), or
# `EffectKind::k...`, naming file:line.
# bench/ keeps its own independent re-implementation on purpose (not
# checked).
#
# Hooks not moved yet are listed in scripts/effect_names_pending.txt as
# "FILE MAX": FILE may hold at most MAX such lines (a ratchet: the count may
# only fall; lower MAX when it does, drop the line at 0).
# Usage: check_effect_names.sh [repo root]   (exit 0 clean, 1 on a violation)
set -euo pipefail
root=${1:-$(cd "$(dirname "$0")/.." && pwd)}
cd "$root"
mapfile -t names < <(grep -ho '^ *: Effect({\.name = "[a-z_0-9]*"\|\.name = "[a-z_0-9]*"' lib/effects/*.cpp |
  sed 's/.*"\(.*\)"/\1/' | sort -u)
if ((${#names[@]} < 19)); then
  echo "check_effect_names: found only ${#names[@]} effect names in lib/effects/*.cpp (expected at least 19)"
  exit 1
fi
# Their parameters' fields in Effects (effects/values.hpp): effect-specific code too.
mapfile -t all_fields < <(grep -ho '&Effects::[a-z_0-9]*' lib/effects/*.cpp | sed 's/&Effects:://' | sort -u)
# A field name that a public struct of lib/ (a header outside lib/effects/) declares
# as a member of its own (NoiseParams::bump_rate, the noise model's bump
# rate) is ambiguous: it counts only when read from an Effects, i.e. through
# `Effects::`, a member called `effects`, or a name the file declares as an
# Effects (`Effects& fx_`).
fields=() ambiguous=()
for f in "${all_fields[@]}"; do
  if grep -rqE "^[[:space:]]*(double|float|int|bool)[[:space:]]+([a-z_0-9]+[^,;]*,[[:space:]]*)*$f[[:space:]]*[=;,]" \
    --include='*.hpp' lib --exclude-dir=effects; then
    ambiguous+=("$f")
  else
    fields+=("$f")
  fi
done
alt() { local IFS='|'; echo "$*"; }
pattern="EffectKind::k[A-Za-z]+|\\b($(alt "${names[@]}"))\\b"
((${#fields[@]})) && pattern+="|[.>]($(alt "${fields[@]}"))\\b"
declare -A pending=()
if [[ -f scripts/effect_names_pending.txt ]]; then
  while read -r file max; do
    [[ -z $file || $file == \#* ]] && continue
    pending[$file]=$max
  done <scripts/effect_names_pending.txt
fi
# The pattern for one file: the ambiguous fields through the file's own
# Effects names.
file_pattern() {
  local p=$pattern vars
  if ((${#ambiguous[@]})); then
    vars=$(sed 's|//.*$||' "$1" | grep -oE '\bEffects[[:space:]]*&?[[:space:]]*[a-z_][a-z_0-9]*' |
      sed -E 's/^Effects[[:space:]]*&?[[:space:]]*//' | sort -u | tr '\n' '|')
    p+="|(Effects::|\\b(${vars}effects)[.])($(alt "${ambiguous[@]}"))\\b"
  fi
  echo "$p"
}
declare -A count=()
hits=()
while IFS= read -r -d '' file; do
  while IFS= read -r hit; do
    [[ -z $hit ]] && continue
    count[$file]=$((${count[$file]:-0} + 1))
    hits+=("$file:$hit")
  done < <(sed 's|//.*$||' "$file" | grep -nE "$(file_pattern "$file")" | cut -c1-160 || true)
done < <(find lib -path lib/effects -prune -o \( -name '*.cpp' -o -name '*.hpp' \) -print0 | sort -z)
status=0
for file in "${!count[@]}"; do
  max=${pending[$file]:-0}
  if ((count[$file] > max)); then
    echo "$file: ${count[$file]} lines name an effect (allowed: $max; move the effect's code into lib/effects/<name>.cpp):"
    for h in "${hits[@]}"; do [[ $h == "$file":* ]] && echo "  $h"; done
    status=1
  fi
done
for file in "${!pending[@]}"; do
  if ((${count[$file]:-0} < pending[$file])); then
    echo "$file: now ${count[$file]:-0} lines name an effect: lower its entry in scripts/effect_names_pending.txt"
    status=1
  fi
done
if ((status == 0)); then
  if ((${#pending[@]} == 0)); then
    echo "effect names: no file outside lib/effects/ names an effect"
  else
    echo "effect names: none outside lib/effects/ beyond scripts/effect_names_pending.txt"
  fi
fi
exit $status
