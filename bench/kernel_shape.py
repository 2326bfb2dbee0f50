#!/usr/bin/env python3
"""The shape figures of issue 43 for a tree: preprocessor branches in kernels/, function-defining and
signature-splicing macros, *_lanes twins, and functions over 80 lines in kernels/ and src/.

    bench/kernel_shape.py [ROOT]                 the figures of a checkout (default: the one this script is in)
    bench/kernel_shape.py --results BASE_COMMIT  BASE_COMMIT's figures against the working tree's, into
                                                 bench/RESULTS.md ("Code shape")

Counted by the rules printed with each figure, so that a later count can be compared with an earlier one."""
import datetime
import pathlib
import re
import subprocess
import sys
import tempfile

HERE = pathlib.Path(__file__).resolve().parent


def figures(root):
    """The figures of the tree at root, as (name, value, detail) rows."""
    return _figures(pathlib.Path(root))


def _figures(root):
    kernel_files = sorted(p for p in (root / "kernels").glob("*") if p.suffix in (".h", ".cl")) + sorted(
        (root / "kernels").glob("*/*.h")) + sorted((root / "kernels").glob("*/*.cl"))
    source_files = sorted(p for p in (root / "src").rglob("*") if p.suffix in (".cpp", ".h"))


    def logical_lines(text):
        """Lines with backslash continuations joined: a macro is one line."""
        return text.replace("\\\n", " ").split("\n")


    branches = 0
    function_macros, splicing_macros = [], []
    lanes_twins = []
    for path in kernel_files:
        text = path.read_text()
        lines = logical_lines(text)
        guard_seen = False
        for line in lines:
            m = re.match(r"\s*#\s*(if|ifdef|ifndef|elif|else)\b", line)
            if m:
                # the include guard is not a branch of the code
                if m.group(1) == "ifndef" and not guard_seen and re.match(r"\s*#\s*ifndef\s+ALGRAY_\w+_H\b", line):
                    guard_seen = True
                    continue
                branches += 1
            d = re.match(r"\s*#\s*define\s+(\w+)(\([^)]*\))?\s*(.*)", line)
            if d:
                name, params, body = d.group(1), d.group(2), d.group(3)
                # a macro whose body defines a function: a declarator followed by a body in braces
                if params and re.search(r"\b\w+\s*\([^)]*\)\s*\{", body) and not body.lstrip().startswith("do"):
                    function_macros.append(f"{path.name}:{name}")
                # a macro spliced into parameter or argument lists: its body starts with a comma, or it is named so
                if re.search(r"_(PARAMS?|ARGS?)$", name) or body.lstrip().startswith(","):
                    splicing_macros.append(f"{path.name}:{name}")
        for m in re.finditer(r"^[A-Za-z_][\w \*]*?\b(\w+_lanes)\s*\(", text, re.M):
            lanes_twins.append(f"{path.name}:{m.group(1)}")

    long_functions = [f for path in kernel_files + source_files for f in _long_functions(path, root)]
    long_functions.sort(reverse=True)
    function_macros = sorted(set(function_macros))
    splicing_macros = sorted(set(splicing_macros))
    return [
        ("#if/#ifdef/#ifndef/#elif/#else lines in kernels/ (include guards left out)", branches, ""),
        ("function-defining macros", len(function_macros), " ".join(function_macros)),
        ("signature-splicing macros (named *_PARAM(S)/*_ARG(S), or a body starting with a comma)",
         len(splicing_macros), " ".join(splicing_macros)),
        ("*_lanes functions", len(set(lanes_twins)), " ".join(sorted(set(lanes_twins)))),
        ("functions over 80 lines in kernels/ and src/", len(long_functions),
         ", ".join(f"{where} ({length})" for length, where in long_functions[:5]) + (", ..." if len(long_functions) > 5 else "")),
    ]


# Functions over 80 lines, by brace matching on the text with comments, literals and preprocessor lines blanked:
# a definition at any depth (members inside a class body too) runs from the line of its name to its closing brace,
# and whatever is defined inside it (lambdas) is part of it. (Until 2026-12-06 the count took only definitions
# that start a line at column 0 and end at a "}" there, which missed members written in class bodies.)
_KEYWORDS = {"if", "for", "while", "switch", "catch", "return", "sizeof", "defined", "alignof", "decltype", "static_assert"}


def _strip(text):
    """Comments, string and character literals and preprocessor lines blanked, newlines kept."""
    out = []
    i, n = 0, len(text)
    line_start = True
    while i < n:
        c = text[i]
        if line_start and c == "#" :
            j = i
            while j < n and (text[j] != "\n" or text[j-1] == "\\"):
                j += 1
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j; continue
        if text.startswith("//", i):
            j = text.find("\n", i); j = n if j < 0 else j
            out.append(" " * (j - i)); i = j; continue
        if text.startswith("/*", i):
            j = text.find("*/", i + 2); j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j; continue
        if text.startswith('R"', i) and (i == 0 or not (text[i-1].isalnum() or text[i-1] == "_")):
            m = re.match(r'R"([^(]*)\(', text[i:])
            if m:
                end = text.find(")" + m.group(1) + '"', i)
                j = n if end < 0 else end + len(m.group(1)) + 2
                out.append(re.sub(r"[^\n]", " ", text[i:j])); i = j; continue
        if c in "\"'":
            if c == "'" and i > 0 and text[i-1].isalnum():  # digit separator 1'000
                out.append(c); i += 1; continue
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (min(j, n) - i - 1) + c); i = j + 1; continue
        out.append(c)
        line_start = c == "\n" or (line_start and c in " \t")
        i += 1
    return "".join(out)

_HEAD = re.compile(r"([~\w:]+)\s*\(([^;{}()]|\([^;{}()]*\))*\)\s*(const\s*)?(noexcept\s*)?(override\s*)?(->\s*[\w:<>&*\s]+?)?\s*(:\s*[^;{}]*?)?\{")


def _long_functions(path, root, limit=80):
    text = _strip(path.read_text())
    found = []
    i = 0
    while True:
        m = _HEAD.search(text, i)
        if not m:
            return found
        name = m.group(1)
        if name.split("::")[-1] in _KEYWORDS:
            i = m.start(1) + len(name)
            continue
        depth, j = 0, m.end() - 1
        while j < len(text):
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            if depth == 0:
                break
            j += 1
        first, last = text.count("\n", 0, m.start(1)) + 1, text.count("\n", 0, j) + 1
        if last - first + 1 > limit:
            found.append((last - first + 1, f"{path.relative_to(root)}:{first} {name}"))
        i = j + 1


def main():
    if len(sys.argv) > 2 and sys.argv[1] == "--results":
        sys.path.insert(0, str(HERE))
        from bench_common import RESULTS_MD, command_line, commit, machine, replace_section
        base = sys.argv[2]
        with tempfile.TemporaryDirectory() as tmp:
            archive = subprocess.run(["git", "-C", str(HERE.parent), "archive", base, "kernels", "src"],
                                     check=True, capture_output=True).stdout
            subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
            before = figures(tmp)
        after = figures(HERE.parent)
        lines = ["### Issue 43's figures", "",
                 f"- Date: {datetime.date.today().isoformat()}; machine: {machine()}; commit: {commit()}",
                 f"- Command: `{command_line()}`; the rules: the script's docstring and issue 43's figures", "",
                 f"| figure | {base[:7]} | now | goal |", "|---|---|---|---|"]
        goals = ["at most 120", "0", "0", "0", "0"]
        for (name, old, _), (_, new, detail), goal in zip(before, after, goals):
            lines.append(f"| {name} | {old} | {new} | {goal} |")
        replace_section(RESULTS_MD, "### Issue 43's figures", "\n".join(lines) + "\n", under="## Code shape")
        print(f"wrote {RESULTS_MD}")
        return
    root = sys.argv[1] if len(sys.argv) > 1 else HERE.parent
    for name, value, detail in figures(root):
        print(f"{name}: {value} {detail}")


if __name__ == "__main__":
    main()
