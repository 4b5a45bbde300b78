#!/usr/bin/env python3
"""Checks that the product's text says what and why, not the history of its work.

Product text is src/, include/, kernels/, bindings/, README.md and docs/
(with bench/RESULTS.md, which docs/performance.md includes). It
fails (exit 1, one `file:line: what` per finding) on
  - references to issues or pull requests ("issue 12", "issues 11 and 12",
    "(issue ...", "#12", "PR 7");
  - work-log words: "this session", "this round", "as before this option
    existed", "appended fields", "this commit", ...;
  - a link of README.md to a file the tree does not hold;
  - a stale DESIGN.md reference (the metrics are in docs/methods.md#metrics);
  - dated measurement notes in code (a date such as 2026-11-23 in src/,
    include/, kernels/ or bindings/: measurements and their dates belong to
    docs/ and commit bodies);
and, inside a git checkout that holds commit a7aeb07 (where the product text
was first cleaned), on commit subjects after it longer than 72 characters.

    python3 scripts/check_product_text.py [--no-commits] [--root DIR]
"""

from __future__ import annotations

import os
import re
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# bench/RESULTS.md is generated, but the performance page shows it as it is
PRODUCT = ["src", "include", "kernels", "bindings", "README.md", "docs", "bench/RESULTS.md"]
CODE = ("src", "include", "kernels", "bindings")  # where a date is a measurement log
TEXT_EXT = {".c", ".h", ".cl", ".py", ".pyi", ".md", ".txt", ".cmake", ".yml", ".yaml",
            ".toml", ".cfg", ".in", ".sh", ".html", ".css", ".js", ".rst"}
SKIP_DIRS = {"__pycache__", ".pytest_cache", "_bin"}
SINCE = "a7aeb07"  # commits after it keep their subjects to 72 characters
MAX_SUBJECT = 72

# (pattern, what) for every file of the product
RULES = [
    (r"\bissues?\s+#?\d+", "issue reference"),
    (r"\bissues?\s+(?:and|or)\s+#?\d+", "issue reference"),
    (r"\(issues?\b", "issue reference"),
    (r"\bissues?-\d+", "issue reference"),  # a heading's anchor
    (r"(?:^|[\s(\[,;])#\d+\b", "issue reference"),
    (r"\b(?:PR|pull request)\s*#?\d+", "pull request reference"),
    # "session" as a period of work; a terminal's or ssh's session is a thing
    (r"(?<!ssh )(?<!terminal )(?<!login )(?<!shell )(?<!interactive )\bsessions?\b",
     "work-log word"),
    # a round of work; the T-junction pass splits faces in rounds ("split this round")
    (r"(?<!split )\b(?:this|last|previous|earlier|next|work|review)\s+round\b(?!s? over)(?!'s)",
     "work-log word"),
    (r"\bas before this\b", "work-log phrase"),
    (r"\bbefore this (?:option|field|change|fix|flag) existed\b", "work-log phrase"),
    (r"\bappended (?:fields?|members?)\b", "work-log phrase"),
    (r"\b(?:fields?|members?) (?:were |was )?appended\b", "work-log phrase"),
    (r"\bthis (?:commit|patch|PR|pull request)\b", "work-log phrase"),
    (r"\b(?:previous|last|earlier) (?:commit|session|round)\b", "work-log phrase"),
    # the metrics live in docs/methods.md#metrics; the repository has no DESIGN.md
    (r"\bDESIGN\.md\b", "stale reference (docs/methods.md#metrics)"),
]
DATE_RULES = [
    (r"\b20\d\d-[01]\d-[0-3]\d\b", "dated note"),
    (r"\b(?:Jan|Feb|Mar|Apr|May|Jun|Jul|Aug|Sep|Oct|Nov|Dec)[a-z]*\.? [0-3]?\d,? 20\d\d\b",
     "dated note"),
]
_RULES = [(re.compile(p, re.I if "PR" not in p else 0), w) for p, w in RULES]
_DATES = [(re.compile(p), w) for p, w in DATE_RULES]


def product_files():
    for top in PRODUCT:
        path = os.path.join(ROOT, top)
        if os.path.isfile(path):
            yield top
            continue
        for d, dirs, files in os.walk(path):
            dirs[:] = sorted(x for x in dirs if x not in SKIP_DIRS and not x.startswith("."))
            for f in sorted(files):
                if os.path.splitext(f)[1] in TEXT_EXT:
                    yield os.path.relpath(os.path.join(d, f), ROOT)


def check_file(rel):
    rules = _RULES + (_DATES if rel.split(os.sep)[0] in CODE else [])
    try:
        with open(os.path.join(ROOT, rel), encoding="utf-8") as fh:
            lines = fh.read().splitlines()
    except (UnicodeDecodeError, OSError):
        return
    for i, line in enumerate(lines, 1):
        for rx, what in rules:
            m = rx.search(line)
            if m:
                yield f"{rel}:{i}: {what}: \"{m.group(0).strip()}\": {line.strip()[:120]}"
                break


def check_readme_links():
    """Every relative link of README.md names a file or folder of the tree."""
    path = os.path.join(ROOT, "README.md")
    if not os.path.isfile(path):
        return
    with open(path, encoding="utf-8") as fh:
        for i, line in enumerate(fh, 1):
            for m in re.finditer(r"\]\(([^)\s]+)\)", line):
                target = m.group(1).split("#", 1)[0]
                if not target or re.match(r"[a-z]+:", target):
                    continue
                if not os.path.exists(os.path.join(ROOT, target)):
                    yield f"README.md:{i}: link to a missing file: {m.group(1)}"


def check_commits():
    def git(*args):
        return subprocess.run(["git", "-C", ROOT, *args], capture_output=True, text=True)

    if git("rev-parse", "--is-inside-work-tree").returncode != 0:
        return
    if git("merge-base", "--is-ancestor", SINCE, "HEAD").returncode != 0:
        return  # a checkout without that history (a shallow clone, an sdist): nothing to check
    log = git("log", "--format=%h %s", f"{SINCE}..HEAD")
    for line in log.stdout.splitlines():
        sha, _, subject = line.partition(" ")
        if len(subject) > MAX_SUBJECT:
            yield (f"commit {sha}: subject of {len(subject)} characters (at most "
                   f"{MAX_SUBJECT}; details go in the body): {subject[:80]}...")


def main(argv):
    global ROOT
    if "--root" in argv:
        ROOT = os.path.abspath(argv[argv.index("--root") + 1])
    findings = []
    for rel in product_files():
        findings.extend(check_file(rel))
    findings.extend(check_readme_links())
    if "--no-commits" not in argv:
        findings.extend(check_commits())
    for f in findings:
        print(f, file=sys.stderr)
    if findings:
        print(f"check_product_text: FAILED: {len(findings)} findings (product text says what and "
              "why; history goes to commit bodies, measurements to docs/performance.md)",
              file=sys.stderr)
        return 1
    print("check_product_text: OK")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
