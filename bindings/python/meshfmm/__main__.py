"""The `meshfmm` command: ``python -m meshfmm ...`` and the ``meshfmm``
console script that ``pip install .`` installs.

The commands are the C command line's (src/cli), built into the wheel as
``meshfmm/_bin/meshfmm``: this wrapper replaces itself with that binary
(os.execv), so arguments, output, signals (Ctrl-C) and exit codes are the
binary's own. Only ``allpairs ... -o OUT.zarr`` (Dask + Zarr) and the
commands in :data:`PYTHON_COMMANDS` (``render``, a picture by
:mod:`meshfmm.plot`; ``isolines``, polylines by :meth:`Mesh.isolines`) are
Python's, dispatched in :func:`main` before the exec; the C command's
``--help`` lists them under "python commands".
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import List, Optional

__all__ = ["main", "cli_path", "PYTHON_COMMANDS"]

_NAME = "meshfmm.exe" if sys.platform == "win32" else "meshfmm"

#: The commands this package runs itself, with the line the C command's
#: ``--help`` gives each (src/cli/main.c lists the same).
PYTHON_COMMANDS = {
    "render": "a PNG of a distance field with isolines and paths (matplotlib)",
    "isolines": "isolines of a distance field as polylines (.obj or .csv)",
}


def _run_python_command(name: str, args: List[str]) -> int:
    if name == "render":
        from .plot import cli_render

        return cli_render(args)
    from ._isolines import cli_isolines

    return cli_isolines(args)


def cli_path() -> Optional[str]:
    """Where the C command line is.

    Returns
    -------
    str or None
        The binary inside the package (a wheel or ``pip install .``), else
        ``$MESHFMM_CLI`` (a development build) when it names an executable
        file, else None.
    """
    inside = Path(__file__).resolve().parent / "_bin" / _NAME
    if inside.is_file() and os.access(inside, os.X_OK):
        return str(inside)
    env = os.environ.get("MESHFMM_CLI")
    if env and os.path.isfile(env) and os.access(env, os.X_OK):
        return env
    return None


def _output(args: List[str]) -> Optional[str]:
    """The value of -o/--output (last one wins), or None."""
    out = None
    for i, a in enumerate(args):
        if a in ("-o", "--output") and i + 1 < len(args):
            out = args[i + 1]
        elif a.startswith("--output="):
            out = a[len("--output="):]
    return out


def _allpairs_zarr(args: List[str]) -> int:
    """`meshfmm allpairs MESH -o OUT.zarr`: the Dask + Zarr job of
    meshfmm.distributed, run by its command line (meshfmm._zarr_cli)."""
    from . import _extras

    try:
        _extras.require("meshfmm allpairs -o OUT.zarr", "dask")
        from ._zarr_cli import cli_allpairs_zarr
    except ImportError as e:
        sys.stderr.write(f"{e}\n")
        return 2
    return cli_allpairs_zarr(args)


def _allpairs_help() -> int:
    """`meshfmm allpairs --help`: the C command line's help (.npy, .npz),
    then the options of the .zarr output this Python command adds."""
    import subprocess

    exe = cli_path()
    if exe is not None:
        sys.stdout.flush()
        subprocess.run([exe, "allpairs", "--help"], check=False)
    else:
        print("meshfmm allpairs: the command-line binary (.npy and .npz outputs) is not "
              "installed with this package")
    print("\nOutput to OUT.zarr (this Python command: a Dask cluster writing a Zarr v3 array,"
          "\nresumable; needs dask[distributed] and zarr>=3):\n")
    try:
        from ._zarr_cli import zarr_parser

        text = zarr_parser().format_help()
    except ImportError as e:
        text = (f"  (its options cannot be listed: {e}); --scheduler, --workers, --resume,\n"
                "  --overwrite, --dtype, --sources, --targets, --max-distance, --cost,\n"
                "  --backend, --method, --exact-start-radius, --plain-start, --block-rows,\n"
                "  --compression, --no-progress, --no-spokes\n")
    sys.stdout.write(text)
    return 0


def main(argv: Optional[List[str]] = None) -> int:
    """Runs the ``meshfmm`` command.

    ``render``, ``isolines`` and ``allpairs ... -o OUT.zarr`` (the Dask +
    Zarr job) run in Python; every other command replaces this process with
    the C command line (``os.execv``), so it does not return.

    Parameters
    ----------
    argv : list of str, optional
        The arguments after the command name; None reads ``sys.argv[1:]``.

    Returns
    -------
    int
        The exit status: 2 when the C command line is not installed, or the
        Zarr job or ``render`` lacks its extra, else the Python command's.
    """
    args = list(sys.argv[1:] if argv is None else argv)
    if args and args[0] == "allpairs" and any(a in ("-h", "--help") for a in args[1:]):
        return _allpairs_help()
    if args and args[0] in PYTHON_COMMANDS:
        return _run_python_command(args[0], args[1:])
    if args and args[0] == "allpairs":
        out = _output(args[1:])
        if out is not None and out.rstrip("/").lower().endswith(".zarr"):
            return _allpairs_zarr(args[1:])
    exe = cli_path()
    if exe is None and (not args or args[0] in ("-h", "--help", "help")):
        # the C command's help lists its own commands; without it, these
        print("usage: meshfmm COMMAND [ARGS]   (meshfmm COMMAND --help for details)\n\n"
              "The command-line binary is not installed with this package; its commands\n"
              "(info, distance, path, allpairs, ...) need `pip install .` at the repository\n"
              "root or MESHFMM_CLI naming a built build/meshfmm.\n\n"
              "python commands (python -m meshfmm COMMAND --help for details):")
        for name, line in PYTHON_COMMANDS.items():
            print(f"  {name:<10} {line}")
        return 0 if args else 2
    if exe is None:
        sys.stderr.write(
            "meshfmm: the command-line binary is not installed with this package "
            f"(looked for {Path(__file__).resolve().parent / '_bin' / _NAME} and $MESHFMM_CLI); "
            "install with `pip install .` at the repository root, or point MESHFMM_CLI "
            "at a built build/meshfmm\n"
        )
        return 2
    sys.stdout.flush()
    sys.stderr.flush()
    # argv[0] "meshfmm", so that usage messages name the command.
    os.execv(exe, ["meshfmm", *args])
    return 127  # not reached


if __name__ == "__main__":
    sys.exit(main())
