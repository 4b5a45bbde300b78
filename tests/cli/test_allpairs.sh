#!/bin/sh
# meshfmm allpairs: the .npy has the right header, shape and dtype and its rows
# equal `meshfmm distance` rows (bit for bit in float64); --sources (.txt and
# .npy); the auto fallback line; SIGINT/SIGTERM leave no file under the final
# name and exit 130.
#   test_allpairs.sh MESHFMM SHARED_DIR [PYTHON]
set -u
M=$1
DATA=$2
PY=${3:-}
if [ -n "$PY" ] && ! "$PY" -c "import numpy" >/dev/null 2>&1; then PY=; fi
T=$(mktemp -d /tmp/mfmm_allpairs.XXXXXX)
trap 'rm -rf "$T"' EXIT
export MESHFMM_CACHE_DIR="$T/cache"
MESH="$DATA/meshes/hand_lowres.obj"
BIG="$DATA/meshes/camelhead.off"
fail() { echo "FAIL: $*" >&2; exit 1; }

# float64 rows of a few sources, on every backend
printf '0 17\n# a comment\n400 809\n3\n' > "$T/src.txt"
for b in auto opencl serial threads; do
    "$M" allpairs "$MESH" -o "$T/d_$b.npy" --dtype float64 --backend $b --sources "$T/src.txt" \
        2> "$T/err_$b.txt" || {
        if [ $b = opencl ] && grep -q "OpenCL" "$T/err_$b.txt"; then
            echo "no OpenCL device: opencl backend skipped"; continue
        fi
        cat "$T/err_$b.txt"; fail "allpairs --backend $b"; }
    grep -q "backend" "$T/err_$b.txt" || fail "no summary line ($b)"
    ls "$T" | grep -q "^d_$b.npy.......$" && fail "temporary file left ($b)"
    # magic and header
    head -c 6 "$T/d_$b.npy" | od -c | head -1 | grep -q "N   U   M   P   Y" || fail "not .npy ($b)"
done
for v in 0 17 400 809 3; do
    "$M" distance "$MESH" --source $v -o "$T/row_$v.npy" || fail "distance --source $v"
done
# the float32 default, all vertices
"$M" allpairs "$MESH" -o "$T/all32.npy" 2> "$T/err32.txt" || { cat "$T/err32.txt"; fail "allpairs float32"; }
grep -q "810 x 810 float32" "$T/err32.txt" || fail "summary line: $(cat "$T/err32.txt")"
# --quiet: nothing on stderr (the OpenCL note and the summary went there too)
"$M" allpairs "$MESH" -o "$T/q.npy" --sources "$T/src.txt" --quiet 2> "$T/errq.txt" || fail "allpairs --quiet"
[ ! -s "$T/errq.txt" ] || fail "--quiet printed: $(cat "$T/errq.txt")"
# float32 .npy: 128-byte header + 810*810*4 bytes
[ "$(wc -c < "$T/all32.npy")" -eq $((128 + 810 * 810 * 4)) ] || fail "float32 file size"

# auto without any OpenCL platform: threads, the summary line saying why
mkdir "$T/no_icd"
OCL_ICD_VENDORS="$T/no_icd" "$M" allpairs "$MESH" -o "$T/fb.npy" --sources "$T/src.txt" \
    --dtype float64 2> "$T/err_fb.txt" || { cat "$T/err_fb.txt"; fail "fallback run"; }
# one calm line: the backend and why, never "falling back"
[ "$(wc -l < "$T/err_fb.txt")" -eq 1 ] || fail "one line: $(cat "$T/err_fb.txt")"
grep -q "backend threads (auto: no OpenCL" "$T/err_fb.txt" || fail "auto's reason: $(cat "$T/err_fb.txt")"
grep -q "falling back" "$T/err_fb.txt" && fail "falling back: $(cat "$T/err_fb.txt")"
cmp "$T/fb.npy" "$T/d_serial.npy" || fail "fallback rows differ from serial"
# memory first: the face walk's rows are the spokes' rows, bit for bit
"$M" allpairs "$MESH" -o "$T/ns.npy" --sources "$T/src.txt" --dtype float64 --backend threads \
    --no-spokes --quiet 2>/dev/null || fail "allpairs --no-spokes"
cmp "$T/ns.npy" "$T/d_serial.npy" || fail "--no-spokes rows differ"
OCL_ICD_VENDORS="$T/no_icd" "$M" allpairs "$MESH" -o "$T/x.npy" --backend opencl 2>/dev/null \
    && fail "opencl without a platform succeeded"
[ -e "$T/x.npy" ] && fail "file written by a failed run"

# usage errors
"$M" allpairs "$MESH" 2>/dev/null; [ $? -eq 2 ] || fail "missing -o is not a usage error"
"$M" allpairs "$MESH" -o "$T/y.npy" --dtype float16 2>/dev/null; [ $? -eq 2 ] || fail "bad dtype"
echo 99999 > "$T/bad.txt"
"$M" allpairs "$MESH" -o "$T/y.npy" --sources "$T/bad.txt" 2>/dev/null && fail "bad source accepted"
[ -e "$T/y.npy" ] && fail "file written for a bad source"

# numbers, with numpy when there is one
if [ -n "$PY" ]; then
    "$PY" - "$T" <<'PYEOF' || fail "numpy checks"
import sys, numpy as np
t = sys.argv[1]
src = [0, 17, 400, 809, 3]
rows = np.stack([np.load(f"{t}/row_{v}.npy") for v in src])
for b in ["auto", "opencl", "serial", "threads"]:
    try:
        d = np.load(f"{t}/d_{b}.npy", mmap_mode="r")
    except FileNotFoundError:
        continue
    assert d.shape == (5, 810) and d.dtype == np.float64, (b, d.shape, d.dtype)
    assert np.array_equal(d.view(np.uint64), rows.view(np.uint64)), b
a = np.load(f"{t}/all32.npy", mmap_mode="r")
assert a.shape == (810, 810) and a.dtype == np.float32
assert np.array_equal(a[src], rows.astype(np.float32))
np.save(f"{t}/src.npy", np.array(src, dtype=np.int64))
np.save(f"{t}/src_i2.npy", np.array(src, dtype=">i2"))
PYEOF
    for f in src.npy src_i2.npy; do
        "$M" allpairs "$MESH" -o "$T/n.npy" --dtype float64 --sources "$T/$f" --quiet \
            2>/dev/null || fail "--sources $f"
        cmp "$T/n.npy" "$T/d_serial.npy" || fail "--sources $f rows differ"
    done
else
    echo "no numpy: value checks skipped"
fi

# SIGINT / SIGTERM / SIGHUP (a closed terminal): exit 130, no file under the final name, no partial file
for sig in INT TERM HUP; do
    "$M" allpairs "$BIG" -o "$T/big.npy" --backend threads --threads 1 --quiet 2>/dev/null &
    pid=$!
    i=0
    while ! ls "$T" | grep -q '^big.npy.......$' && [ $i -lt 200 ]; do sleep 0.05; i=$((i + 1)); done
    sleep 0.3
    kill -$sig $pid
    wait $pid
    rc=$?
    [ $rc -eq 130 ] || fail "SIG$sig: exit status $rc, not 130"
    [ -e "$T/big.npy" ] && fail "SIG$sig left $T/big.npy"
    ls "$T" | grep -q '^big.npy.......$' && fail "SIG$sig left the temporary file"
done
echo "allpairs CLI: all checks passed"
