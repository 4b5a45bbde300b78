"""MkDocs hook: the performance page includes bench/RESULTS.md as generated.

bench/RESULTS.md is written by bench/suite/make_results_md.py from the raw
results (bench/results/*.json) and never edited by hand; the page's marker
``<!-- bench-results -->`` is replaced by it at build time, its headings one
level down and its links rewritten for the site (../docs/X -> X, an image or
a page; other relative links -> the file's path in the repository, as code).
"""

from __future__ import annotations

import re
from pathlib import Path

try:  # a clean "Error: ..." from mkdocs, no traceback
    from mkdocs.exceptions import PluginError as BuildError
except ImportError:  # run alone: python docs/hooks/...
    BuildError = RuntimeError

MARKER = "<!-- bench-results -->"
RESULTS = Path(__file__).resolve().parents[2] / "bench" / "RESULTS.md"


def render(path: Path = RESULTS) -> str:
    if not path.is_file():
        raise BuildError(f"performance page: {path} not found (bench/suite/run_all.sh writes it)")
    out, fenced = [], False
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
        elif not fenced:
            if line.startswith("#"):
                line = "#" + line
            line = line.replace("](../docs/", "](")  # images and pages of this site
            # links to repository files (not pages of this site): shown as paths
            line = re.sub(r"\[([^\]]+)\]\((?!images/|https?:|#|[\w-]+\.md\b)([^)]+)\)",
                          r"\1 (`\2`)", line)
        out.append(line)
    return "\n".join(out)


def on_page_markdown(markdown, page, config, files):
    if MARKER not in markdown:
        return markdown
    return markdown.replace(MARKER, render())
