#!/usr/bin/env python3
"""Function lengths in C++ sources, lambdas counted inside the function that
holds them (the style guide: none over 120 lines; over ~80 a comment says
why). Lines run from the first line of the signature to the closing brace.

Usage: check_function_length.py [--max N] [--report M] (--root DIR | FILE...)
  --root DIR  every .cpp/.hpp under DIR's lib apps tests bench fuzz python
              include examples (the ctest `function_length`)
Prints every function longer than M lines (default: N) as FILE:LINE: N
lines: NAME; exits 1 when one is longer than N (default 120).

A brace scanner, not a parser: comments and literals are blanked, and a
brace opens a function body when the code before it ends in a parameter
list (with qualifiers, a trailing return type or an initializer list)
that no `if`/`for`/`while`/`switch`/`catch` or `=` introduces."""
import pathlib
import re
import sys

CONTROL = re.compile(r'\b(if|for|while|switch|catch|else|do|try)\s*$')


def strip(text):
    """Comments, string and character literals blanked (newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith('//', i):
            j = text.find('\n', i)
            j = n if j < 0 else j
            out.append(' ' * (j - i)); i = j
        elif text.startswith('/*', i):
            j = text.find('*/', i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j])); i = j
        elif text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == '_')):
            m = re.match(r'R"([^(\s]*)\(', text[i:])
            end = text.find(')' + m.group(1) + '"', i) if m else -1
            j = n if end < 0 else end + len(m.group(1)) + 2
            out.append(re.sub(r'[^\n]', ' ', text[i:j])); i = j
        elif c in '"\'':
            if c == "'" and i > 0 and text[i - 1].isalnum():  # digit separator 1'000
                out.append(' '); i += 1; continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == '\\' else 1
            j = min(j + 1, n)
            out.append(re.sub(r'[^\n]', ' ', text[i:j])); i = j
        else:
            out.append(c); i += 1
    return ''.join(out)


def is_function_body(before):
    """`before`: the code between the previous ; { } and this {."""
    s = before.strip()
    if not s or s.startswith('#'):
        return False
    # Drop trailing qualifiers and a trailing return type.
    s = re.sub(r'(\b(const|override|final|noexcept|mutable|volatile)\b|&&|&|\s)+$', '', s)
    s = re.sub(r'->\s*[\w:<>,\s*&]+$', '', s).rstrip()
    s = re.sub(r'\bnoexcept\s*\([^()]*\)$', '', s).rstrip()
    if not s.endswith(')'):
        # A constructor's initializer list: "X::X(...) : a_(x), b_{y}".
        return bool(re.search(r'\)\s*:\s*\w', s)) and s.endswith((')', '}'))
    # Find the matching ( of the final ).
    depth, k = 0, len(s) - 1
    while k >= 0:
        if s[k] == ')': depth += 1
        elif s[k] == '(':
            depth -= 1
            if depth == 0: break
        k -= 1
    head = s[:k].rstrip()
    if CONTROL.search(head) or head.endswith(('=', 'return', ',', '(')):
        return False
    if head.endswith(']') or head.endswith('>') and '[' in head[-3:]:
        return False  # a lambda outside a function (a static initialiser)
    return bool(re.search(r'[\w>~=\]]$', head))


def functions(path):
    text = strip(open(path, encoding='utf-8', errors='replace').read())
    line_of = []
    ln = 1
    for ch in text:
        line_of.append(ln)
        if ch == '\n': ln += 1
    stack = []          # per open brace: True when it opens a function body
    inside = 0          # open function bodies (the outermost counts)
    start_stmt = 0
    found = []
    for i, ch in enumerate(text):
        if ch == '{':
            fn = inside == 0 and is_function_body(text[start_stmt:i])
            if fn:
                seg = text[start_stmt:i]
                first = start_stmt + len(seg) - len(seg.lstrip())
                name = re.search(r'([~\w:]+(?:<[^()]*>)?|operator\S*)\s*\(', seg)
                found_start = (line_of[first], name.group(1) if name else '?')
            stack.append(fn)
            if fn:
                inside += 1
                current = found_start
            elif inside:
                inside += 1
            start_stmt = i + 1
        elif ch == '}':
            if stack:
                fn = stack.pop()
                if inside:
                    inside -= 1
                    if inside == 0:
                        found.append((current[0], line_of[i] - current[0] + 1, current[1]))
            start_stmt = i + 1
        elif ch == ';' and not inside:
            start_stmt = i + 1
        elif ch == ';':
            start_stmt = i + 1
    return found


def self_test():
    """The scanner on made-up code whose lengths are known."""
    import tempfile
    body = '\n'.join(f'  x += {i};' for i in range(115))
    code = (
        'namespace a {\n'                                  # 1
        'struct S {\n'                                     # 2
        '  int Get() const { return 1; }\n'                # 3: 1 line
        '};\n'                                             # 4
        'int Long(int x,\n'                                # 5
        '         int y) {\n'                              # 6
        '  auto f = [&](int k) {\n'                        # 7: a lambda counts inside
        '    if (k) { return "}}}"; }\n'                   # 8: braces in a string
        '    return "{";\n'
        '  };\n'
        + body + '\n'
        '  return x;\n'
        '}\n'
        '}  // namespace a\n')
    with tempfile.NamedTemporaryFile('w', suffix='.cpp', delete=False) as f:
        f.write(code)
    got = {name: (line, n) for line, n, name in functions(f.name)}
    pathlib.Path(f.name).unlink()
    want = {'Get': (3, 1), 'Long': (5, 5 + 115 + 3)}
    if got != want:
        print(f'self-test failed: {got} != {want}', file=sys.stderr)
        return 1
    return 0


def main(argv):
    if argv == ['--self-test']:
        return self_test()
    limit, report, files = 120, None, []
    it = iter(argv)
    for a in it:
        if a == '--max': limit = int(next(it))
        elif a == '--report': report = int(next(it))
        elif a == '--root':
            root = pathlib.Path(next(it))
            for sub in ('lib', 'apps', 'tests', 'bench', 'fuzz', 'python', 'include', 'examples'):
                files += sorted(str(f) for f in (root / sub).rglob('*') if f.suffix in ('.cpp', '.hpp'))
        else: files.append(a)
    report = limit if report is None else report
    bad = 0
    for p in files:
        for line, n, name in functions(p):
            if n > report:
                print(f'{p}:{line}: {n} lines: {name}')
            if n > limit:
                bad += 1
    if bad:
        print(f'{bad} function(s) over {limit} lines (lambdas counted): split them', file=sys.stderr)
    return 1 if bad else 0


if __name__ == '__main__':
    sys.exit(main(sys.argv[1:]))
