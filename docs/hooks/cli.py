"""MkDocs hook: the command-line page (docs/cli.md) generated from the help texts.

Runs the built command line (``$MESHFMM_CLI``, else ``build/meshfmm``):
``meshfmm --help``, then ``meshfmm COMMAND --help`` for every command that
help lists under "commands:", ``python -m meshfmm COMMAND --help`` for every
one it lists under "python commands" (render, isolines: the Python
package's), and ``python -m meshfmm.distributed --help`` (the Dask + Zarr
job behind ``meshfmm allpairs ... -o OUT.zarr``) when that module exists.
The page holds only a marker (``<!-- cli -->``) that this hook replaces, so
the page says what the binary says. Without a built binary the build fails:
build first (see the message).
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

try:  # a clean "Error: ..." from mkdocs, no traceback
    from mkdocs.exceptions import PluginError as BuildError
except ImportError:  # run alone: python docs/hooks/...
    BuildError = RuntimeError

MARKER = "<!-- cli -->"
REPO = Path(__file__).resolve().parents[2]


def _cli() -> Path:
    cli = Path(os.environ.get("MESHFMM_CLI") or REPO / "build" / "meshfmm")
    if not (cli.is_file() and os.access(cli, os.X_OK)):
        raise BuildError(
            f"cli page: the meshfmm command line was not found at {cli}. Build it first "
            "(cmake -S . -B build -DCMAKE_BUILD_TYPE=Release && cmake --build build), "
            "or point MESHFMM_CLI at a built meshfmm binary.")
    return cli


def _run(argv, env=None) -> str:
    r = subprocess.run(argv, capture_output=True, text=True, env=env, timeout=120)
    if r.returncode != 0:
        raise BuildError(f"cli page: `{' '.join(map(str, argv))}` exited {r.returncode}: "
                           f"{r.stderr.strip()[:500]}")
    return r.stdout if r.stdout.strip() else r.stderr


def _commands(top: str, section: str = "commands"):
    """The commands `meshfmm --help` lists in the section whose heading (a
    line ending in ":") starts with `section`."""
    out, inside = [], False
    for line in top.splitlines():
        if re.match(r"^\S.*:\s*$", line):
            inside = line.strip().lower().startswith(section)
            continue
        if not line.strip():
            continue
        m = re.match(r"^\s{1,8}([a-z][\w-]*)\s{2,}", line)
        if inside and m:
            out.append(m.group(1))
        elif not line.startswith(" "):
            inside = False  # a paragraph after the list ends the section
    return out


def _python_env() -> dict:
    env = dict(os.environ)
    env.setdefault("PYTHONPATH", str(REPO / "bindings" / "python"))
    lib = REPO / "build" / "libmeshfmm.so"
    if "MESHFMM_LIBRARY" not in env and lib.is_file():
        env["MESHFMM_LIBRARY"] = str(lib)
    env["COLUMNS"] = "88"  # argparse wraps to it: the same page on every terminal
    return env


def _block(text: str) -> list:
    return ["```text", text.rstrip("\n"), "```", ""]


def render() -> str:
    cli = _cli()
    top = _run([str(cli), "--help"])
    md = ["## meshfmm", ""] + _block(top)
    commands = _commands(top)
    if not commands:
        raise BuildError("cli page: `meshfmm --help` lists no commands under \"commands:\"")
    for c in commands:
        md += [f"## meshfmm {c}", ""] + _block(_run([str(cli), c, "--help"]))
    env = _python_env()
    for c in _commands(top, "python commands"):
        md += [f"## meshfmm {c}", "",
               f"A command of the Python package's `meshfmm` (`python -m meshfmm {c}`, or the "
               "`meshfmm` that pip installs), not of the C command line.", ""]
        md += _block(_run([sys.executable, "-m", "meshfmm", c, "--help"], env=env))
    probe = subprocess.run([sys.executable, "-c",
                            "import importlib.util as u, sys; "
                            "sys.exit(0 if u.find_spec('meshfmm.distributed') else 3)"],
                           capture_output=True, text=True, env=env)
    if probe.returncode == 0:
        md += ["## python -m meshfmm.distributed", "",
               "The Dask + Zarr job: what `meshfmm allpairs MESH -o OUT.zarr` runs when the "
               "`meshfmm` command comes from the Python package (`pip install .`).", ""]
        md += _block(_run([sys.executable, "-m", "meshfmm.distributed", "--help"], env=env))
    return "\n".join(md)


def on_page_markdown(markdown, page, config, files):
    if MARKER not in markdown:
        return markdown
    return markdown.replace(MARKER, render())


if __name__ == "__main__":  # python docs/hooks/cli.py: print the page body
    print(render())
