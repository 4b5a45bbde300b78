"""The ctypes mirrors in meshfmm._lib against the C compiler's layout of
include/meshfmm.h: sizeof and every offsetof, from a tiny C program."""

from __future__ import annotations

import ctypes
import json
import shutil
import subprocess

import numpy as np
import pytest

from conftest import REPO
from meshfmm import _lib

STRUCTS = {
    "mfmm_error": _lib.mfmm_error,
    "mfmm_mesh_options": _lib.mfmm_mesh_options,
    "mfmm_mesh_info": _lib.mfmm_mesh_info,
    "mfmm_source": _lib.mfmm_source,
    "mfmm_solve_options": _lib.mfmm_solve_options,
    "mfmm_solve_info": _lib.mfmm_solve_info,
    "mfmm_exact_options": _lib.mfmm_exact_options,
    "mfmm_exact_info": _lib.mfmm_exact_info,
    "mfmm_surface_point": _lib.mfmm_surface_point,
    "mfmm_path_options": _lib.mfmm_path_options,
    "mfmm_matrix_options": _lib.mfmm_matrix_options,
    "mfmm_matrix_info": _lib.mfmm_matrix_info,
    "mfmm_opencl_options": _lib.mfmm_opencl_options,
}
ENUMS = ["mfmm_status", "mfmm_cost_location", "mfmm_backend", "mfmm_dtype"]


@pytest.fixture(scope="module")
def c_layout(tmp_path_factory):
    cc = shutil.which("cc") or shutil.which("gcc") or shutil.which("clang")
    if cc is None:
        pytest.skip("no C compiler to check struct layouts against")
    lines = ['#include <stdio.h>', '#include <stddef.h>', '#include "meshfmm.h"',
             "int main(void) {", '  printf("{");']
    first = True
    for name, st in STRUCTS.items():
        for field, _ in st._fields_:
            sep = "" if first else ","
            first = False
            lines.append(f'  printf("{sep}\\"{name}.{field}\\": %zu", offsetof({name}, {field}));')
        lines.append(f'  printf(",\\"sizeof {name}\\": %zu", sizeof({name}));')
    for name in ENUMS:
        lines.append(f'  printf(",\\"sizeof {name}\\": %zu", sizeof({name}));')
    lines.append('  printf(",\\"sizeof mfmm_rows_callback\\": %zu", sizeof(mfmm_rows_callback));')
    # enum values the binding hard-codes
    for const in ["MFMM_STATUS_COUNT", "MFMM_ERR_PARSE", "MFMM_ERR_OUT_OF_MEMORY",
                  "MFMM_ERR_CANCELLED", "MFMM_ERR_IO", "MFMM_COST_PER_FACE",
                  "MFMM_BACKEND_OPENCL", "MFMM_FLOAT64", "MFMM_VERSION_MAJOR",
                  "MFMM_VERSION_MINOR"]:
        lines.append(f'  printf(",\\"{const}\\": %d", (int){const});')
    lines += ['  printf("}\\n");', "  return 0;", "}"]
    d = tmp_path_factory.mktemp("abi")
    (d / "abi.c").write_text("\n".join(lines))
    subprocess.run([cc, "-std=c99", "-I", str(REPO / "include"), "abi.c", "-o", "abi"],
                   cwd=d, check=True)
    out = subprocess.run([str(d / "abi")], check=True, capture_output=True, text=True).stdout
    return json.loads(out)


@pytest.mark.parametrize("name", sorted(STRUCTS))
def test_struct_layout(c_layout, name):
    st = STRUCTS[name]
    for field, _ in st._fields_:
        assert getattr(st, field).offset == c_layout[f"{name}.{field}"], f"{name}.{field}"
    assert ctypes.sizeof(st) == c_layout[f"sizeof {name}"]


def test_enums_and_callback(c_layout):
    for name in ENUMS:
        assert c_layout[f"sizeof {name}"] == ctypes.sizeof(_lib.c_enum)
    assert c_layout["sizeof mfmm_rows_callback"] == ctypes.sizeof(ctypes.c_void_p)
    assert c_layout["MFMM_STATUS_COUNT"] == _lib.MFMM_STATUS_COUNT
    assert c_layout["MFMM_ERR_PARSE"] == _lib.MFMM_ERR_PARSE
    assert c_layout["MFMM_ERR_OUT_OF_MEMORY"] == _lib.MFMM_ERR_OUT_OF_MEMORY
    assert c_layout["MFMM_ERR_CANCELLED"] == _lib.MFMM_ERR_CANCELLED
    assert c_layout["MFMM_ERR_IO"] == _lib.MFMM_ERR_IO
    assert c_layout["MFMM_COST_PER_FACE"] == _lib.MFMM_COST_PER_FACE
    assert c_layout["MFMM_BACKEND_OPENCL"] == _lib.MFMM_BACKEND_OPENCL
    assert c_layout["MFMM_FLOAT64"] == _lib.MFMM_FLOAT64
    # the mirrors are of this header's ABI, and the loaded library speaks it
    assert (c_layout["MFMM_VERSION_MAJOR"], c_layout["MFMM_VERSION_MINOR"]) == _lib.ABI_VERSION
    assert tuple(int(x) for x in _lib.version().split(".")[:2]) == _lib.ABI_VERSION


def test_struct_size_first_and_set():
    """Every struct that can grow starts with struct_size, and a new mirror
    has it set to its sizeof (output structs are passed as they are)."""
    for name, st in STRUCTS.items():
        if st._fields_[0][0] != "struct_size":
            assert name in ("mfmm_error", "mfmm_source", "mfmm_surface_point"), name
            continue
        assert st().struct_size == ctypes.sizeof(st), name


def test_numpy_record_layouts():
    """The numpy views used for arrays of sources and path points."""
    for dt, st in ((_lib.SOURCE_DTYPE, _lib.mfmm_source),
                   (_lib.SURFACE_POINT_DTYPE, _lib.mfmm_surface_point)):
        assert dt.itemsize == ctypes.sizeof(st)
        for field in dt.names:
            assert dt.fields[field][1] == getattr(st, field).offset
    # round trip one record through both views
    rec = np.zeros(1, dtype=_lib.SOURCE_DTYPE)
    rec["vertex"], rec["face"], rec["bary"], rec["value"] = 7, 3, (0.25, 0.5, 0.25), 1.5
    c = _lib.mfmm_source.from_buffer(rec)
    assert (c.vertex, c.face, list(c.bary), c.value) == (7, 3, [0.25, 0.5, 0.25], 1.5)


def test_status_strings_and_version():
    import meshfmm

    assert meshfmm.__version__.count(".") == 2
    for s in range(_lib.MFMM_STATUS_COUNT):
        assert _lib.status_string(s)
    assert _lib.status_string(_lib.MFMM_STATUS_COUNT + 5)  # never NULL
