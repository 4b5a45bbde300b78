"""MkDocs hook: the C API page (docs/c-api.md) generated from include/meshfmm.h.

The page is the header's contract, read at build time: its opening comment,
then each section (a comment line such as ``/* ---- mesh */``) with its prose
comments and each declaration with the comment above it, in header order. The
page holds only a marker (``<!-- c-api -->``) that this hook replaces, so the
text can never drift from the header.
"""

from __future__ import annotations

import html
import re
from pathlib import Path

try:  # a clean "Error: ..." from mkdocs, no traceback
    from mkdocs.exceptions import PluginError as BuildError
except ImportError:  # run alone: python docs/hooks/...
    BuildError = RuntimeError

MARKER = "<!-- c-api -->"
HEADER = Path(__file__).resolve().parents[2] / "include" / "meshfmm.h"

# a section rule: "/* ---- name */", "/* ==== name ==== */", "/* ## name */"
_RULE = re.compile(r"^[\s\-=#*]{3,}\s*(.*?)\s*[\-=#*\s]*$")
_SKIP_DEFINES = {"MFMM_API", "MESHFMM_H"}


def _scan(text: str):
    """Items of the header in order: ("comment", text, blank_after),
    ("decl", text, blank_after) and ("pp", text, blank_after)."""
    items = []
    i, n = 0, len(text)
    while i < n:
        c = text[i]
        if c in " \t\n":
            i += 1
            continue
        start = i
        if text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            kind = "comment"
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            kind = "comment"
        elif c == "#":
            j = i
            while True:  # a preprocessor line with its continuations
                k = text.find("\n", j)
                k = n if k < 0 else k
                if text[j:k].rstrip().endswith("\\") and k < n:
                    j = k + 1
                    continue
                j = k
                break
            kind = "pp"
        else:  # a declaration: up to ";" at depth 0 (skipping comments and strings)
            depth, j = 0, i
            while j < n:
                if text.startswith("/*", j):
                    k = text.find("*/", j + 2)
                    j = n if k < 0 else k + 2
                    continue
                ch = text[j]
                if ch == '"':
                    k = j + 1
                    while k < n and text[k] != '"':
                        k += 2 if text[k] == "\\" else 1
                    j = k + 1
                    continue
                if ch in "{(":
                    depth += 1
                elif ch in "})":
                    depth -= 1
                    if depth < 0:  # the closing brace of extern "C" {
                        j += 1
                        break
                elif ch == ";" and depth == 0:
                    j += 1
                    break
                j += 1
            kind = "decl"
        chunk = text[start:j]
        # extern "C" { and its closing brace: noise, like the preprocessor lines
        if kind == "decl" and (chunk.startswith("extern") or chunk.strip() == "}"):
            line_end = text.find("\n", start)
            j = n if line_end < 0 else line_end
            chunk, kind = text[start:j], "pp"
        rest = text[j:]
        blank_after = bool(re.match(r"[ \t]*\n[ \t]*\n", rest)) or not rest.strip()
        items.append((kind, chunk, blank_after))
        i = j
    return items


def _comment_text(raw: str) -> str:
    """The text of a comment, its delimiters and leading " * " removed."""
    if raw.startswith("//"):
        return raw[2:].strip()
    body = raw[2:-2]
    lines = body.split("\n")
    out = []
    for ln in lines:
        s = ln.rstrip()
        s = re.sub(r"^\s*\* ?", "", s) if re.match(r"^\s*\*", s) else s.strip() if not out else s
        out.append(s)
    while out and not out[0].strip():
        out.pop(0)
    while out and not out[-1].strip():
        out.pop()
    # common indentation
    ind = min((len(s) - len(s.lstrip()) for s in out if s.strip()), default=0)
    return "\n".join(s[ind:] for s in out)


def _section_title(raw: str):
    """The title of a section rule comment, or None."""
    if "\n" in raw.strip():
        first = raw.strip().split("\n", 1)[0]
    else:
        first = raw.strip()
    inner = first[2:]
    inner = inner[:-2] if inner.endswith("*/") else inner
    if not re.match(r"^\s*[-=#*]{3,}", inner) and not re.search(r"[-=#*]{3,}\s*$", inner):
        return None
    title = re.sub(r"^[\s\-=#*]+|[\s\-=#*]+$", "", inner)
    return title or None


def _names(decl: str):
    """The names a declaration introduces (for the headings and anchors)."""
    d = re.sub(r"/\*.*?\*/", "", decl, flags=re.S).strip()
    m = re.match(r"#\s*define\s+(\w+)", d)
    if m:
        return [m.group(1)]
    m = re.match(r"(struct|enum|union)\s+(\w+)\s*\{", d)
    if m:  # struct name { ... };
        return [m.group(2)]
    if d.startswith("typedef") and "{" in d:  # typedef struct/enum x { ... } name;
        m = re.search(r"\}\s*(\w+)", d[d.rfind("}"):])
        return [m.group(1)] if m else []
    m = re.search(r"\(\s*\*\s*(\w+)\s*\)\s*\(", d)  # function pointer typedef
    if m and d.startswith("typedef"):
        return [m.group(1)]
    if d.startswith("typedef"):
        m = re.search(r"(\w+)\s*(\[[^\]]*\])?\s*;\s*$", d)
        return [m.group(1)] if m else []
    m = re.search(r"(\w+)\s*\(", d)
    return [m.group(1)] if m else []


def _escape_md(text: str) -> str:
    """Comment prose as Markdown: keep `code` spans, escape the rest."""
    parts = re.split(r"(`[^`\n]*`)", text)
    out = []
    for p in parts:
        if p.startswith("`") and p.endswith("`") and len(p) > 1:
            out.append(p)
        else:
            p = html.escape(p, quote=False)
            out.append(re.sub(r"([\\*_\[\]#|])", r"\\\1", p))
    lines = "".join(out).split("\n")
    # keep the header's line structure (lists, indented parameter lists)
    return "  \n".join(ln.replace("  ", "&nbsp; ") if ln.startswith("  ") else ln for ln in lines)


def render(header: Path = HEADER) -> str:
    if not header.is_file():
        raise BuildError(f"c-api page: {header} not found")
    text = header.read_text(encoding="utf-8")
    items = _scan(text)
    md = []
    k = 0
    # the opening comment: the header's conventions
    if items and items[0][0] == "comment":
        md += ["## Overview", "", "```c", items[0][1], "```", ""]
        k = 1
    pending = None  # a comment waiting for the declaration under it
    group = None  # (names, code lines) of the entry being built

    def flush():
        nonlocal group
        if group:
            names, code = group
            md.append("### " + (names[0] if names else "declaration"))
            if len(names) > 1:
                md.append("")
                md.append("Also: " + ", ".join(f"`{x}`" for x in names[1:]))
            md.extend(["", "```c", "\n".join(code), "```", ""])
        group = None

    for kind, chunk, blank_after in items[k:]:
        if kind == "pp":
            m = re.match(r"#\s*define\s+(\w+)", chunk)
            if not m or m.group(1) in _SKIP_DEFINES:
                if pending is not None:  # a comment above #if ...: prose
                    md += [_escape_md(_comment_text(pending)), ""]
                    pending = None
                continue
            kind = "decl"
        if kind == "comment":
            title = _section_title(chunk)
            if title is not None:
                flush()
                if pending is not None:
                    md += [_escape_md(_comment_text(pending)), ""]
                    pending = None
                md += [f"## {title[0].upper() + title[1:]}", ""]
                rest = chunk.strip().split("\n", 1)
                if len(rest) > 1:
                    body = _comment_text("/*" + rest[1])
                    if body.strip():
                        md += [_escape_md(body), ""]
                continue
            flush()
            if pending is not None:
                md += [_escape_md(_comment_text(pending)), ""]
            pending = chunk
            if blank_after:  # a comment standing alone: prose of the section
                md += [_escape_md(_comment_text(pending)), ""]
                pending = None
            continue
        # a declaration
        code = []
        if pending is not None:
            code.append(pending)
            pending = None
        code.append(chunk.strip("\n"))
        if group is None:
            group = (_names(chunk), code)
        else:
            group[0].extend(_names(chunk))
            group[1].extend(code)
        if blank_after:
            flush()
    flush()
    if pending is not None:
        md += [_escape_md(_comment_text(pending)), ""]
    return "\n".join(md)


def on_page_markdown(markdown, page, config, files):
    if MARKER not in markdown:
        return markdown
    return markdown.replace(MARKER, render())


if __name__ == "__main__":  # python docs/hooks/c_api.py: print the page body
    print(render())
