#!/bin/sh
# Command-line tests: test_cli.sh PATH/TO/meshfmm SHARED_DIR
# Checks exit statuses and messages, info's counts for hand_lowres.obj, and
# distances on a generated grid against the exact values along its edges.
set -u
BIN=${1:?usage: test_cli.sh MESHFMM SHARED_DIR}
DATA=${2:?usage: test_cli.sh MESHFMM SHARED_DIR}
[ -x "$BIN" ] || { echo "FAIL: no executable $BIN"; exit 1; }
T=$(mktemp -d "${TMPDIR:-/tmp}/mfmm_cli.XXXXXX") || exit 1
trap 'rm -rf "$T"' EXIT INT TERM
FAILS=0

fail() { echo "FAIL: $*"; FAILS=$((FAILS + 1)); }
ok() { echo "ok: $*"; }

# expect STATUS DESCRIPTION -- command...: runs it, checks its exit status.
expect() {
    want=$1; what=$2; shift 2
    "$@" >"$T/out" 2>"$T/err"
    got=$?
    if [ "$got" -ne "$want" ]; then
        fail "$what: exit $got, want $want; stderr: $(cat "$T/err")"
        return 1
    fi
    if [ "$want" -ne 0 ]; then
        # One clear line on stderr starting with "meshfmm".
        if ! grep -q '^meshfmm' "$T/err"; then
            fail "$what: no 'meshfmm...' message on stderr"
            return 1
        fi
    fi
    ok "$what"
    return 0
}

# value KEY FILE: the number after "KEY:" in info's text output.
value() { awk -F: -v k="$1" '$1 == k { gsub(/ /, "", $2); print $2 }' "$2"; }

# ---- version, help, usage ----
expect 0 "--version" "$BIN" --version && grep -q '^meshfmm [0-9]*\.[0-9]*\.[0-9]*$' "$T/out" ||
    fail "--version output: $(cat "$T/out")"
expect 0 "--help" "$BIN" --help
for c in info distance generate; do
    expect 0 "$c --help" "$BIN" "$c" --help && grep -q "usage: meshfmm $c" "$T/out" ||
        fail "$c --help text"
done
expect 2 "no command" "$BIN"
expect 2 "unknown command" "$BIN" frobnicate
expect 2 "info without a mesh" "$BIN" info
expect 2 "info unknown option" "$BIN" info --bogus x.obj
expect 2 "distance without a source" "$BIN" distance "$DATA/meshes/hand_lowres.obj" -o "$T/d.txt"
expect 2 "distance without -o" "$BIN" distance "$DATA/meshes/hand_lowres.obj" --source 0
expect 2 "distance bad output extension" "$BIN" distance "$DATA/meshes/hand_lowres.obj" --source 0 -o "$T/d.csv"
expect 2 "distance bad source number" "$BIN" distance "$DATA/meshes/hand_lowres.obj" --source 1x -o "$T/d.txt"
expect 2 "generate unknown shape" "$BIN" generate cube 3 -o "$T/c.obj"
expect 2 "generate bad N" "$BIN" generate grid 0 -o "$T/c.obj"

# ---- info on hand_lowres.obj: README counts ----
if expect 0 "info hand_lowres.obj" "$BIN" info "$DATA/meshes/hand_lowres.obj"; then
    for kv in "vertices=810" "faces=1602" "edges=2411" "boundary edges=16" "components=1" \
              "non-manifold edges=0" "unreferenced vertices=0"; do
        k=${kv%=*}; v=${kv#*=}
        got=$(value "$k" "$T/out")
        [ "$got" = "$v" ] && ok "info: $k = $v" || fail "info: $k = '$got', want $v"
    done
fi
if expect 0 "info --json" "$BIN" info --json "$DATA/meshes/hand_lowres.obj"; then
    grep -q '"vertices": 810, "faces": 1602, "edges": 2411, "boundary_edges": 16, "nonmanifold_edges": 0, "components": 1' "$T/out" &&
        ok "info --json counts" || fail "info --json: $(cat "$T/out")"
fi
# beetle: 2 components, 47 non-manifold edges; bunny: 1113 unreferenced vertices.
expect 0 "info beetle.obj" "$BIN" info "$DATA/meshes/beetle.obj" &&
    { [ "$(value components "$T/out")" = 2 ] && [ "$(value "non-manifold edges" "$T/out")" = 47 ] &&
      ok "beetle counts" || fail "beetle counts: $(cat "$T/out")"; }
expect 0 "info stanford-bunny.obj" "$BIN" info "$DATA/meshes/stanford-bunny.obj" &&
    { [ "$(value "unreferenced vertices" "$T/out")" = 1113 ] && ok "bunny unreferenced" ||
      fail "bunny unreferenced: $(cat "$T/out")"; }

# ---- broken files: exit 1 with a message ----
printf '' >"$T/empty.obj"
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n' >"$T/range.obj"
printf 'OFF\n3 1 0\n0 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n' >"$T/nan.off"
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 2147483647\nproperty float x\nend_header\n' >"$T/huge.ply"
head -c 1000 "$DATA/meshes/igea.ply" >"$T/cut.ply"
head -c 3000 /dev/urandom >"$T/noise.off" 2>/dev/null || printf '\001\002garbage' >"$T/noise.off"
for f in empty.obj range.obj nan.off huge.ply cut.ply noise.off missing.obj; do
    expect 1 "info $f fails" "$BIN" info "$T/$f"
    expect 1 "distance $f fails" "$BIN" distance "$T/$f" --source 0 -o "$T/bad.txt"
done
grep -q 'line 4' "$T/err" 2>/dev/null || true
"$BIN" info "$T/range.obj" 2>"$T/err"
grep -q 'range.obj: line 4' "$T/err" && ok "message names the line" || fail "message: $(cat "$T/err")"
[ ! -e "$T/bad.txt" ] && [ ! -e "$T/bad.txt.partial" ] && ok "no output after a failure" ||
    fail "output left behind after a failure"

# ---- generate ----
expect 0 "generate sphere 2" "$BIN" generate sphere 2 -o "$T/s.obj" &&
    expect 0 "info sphere" "$BIN" info "$T/s.obj" &&
    { [ "$(value vertices "$T/out")" = 162 ] && [ "$(value faces "$T/out")" = 320 ] &&
      [ "$(value "boundary edges" "$T/out")" = 0 ] && ok "icosphere level 2 counts" ||
      fail "icosphere counts: $(cat "$T/out")"; }
for s in sine torus lattice; do
    expect 0 "generate $s 6" "$BIN" generate "$s" 6 -o "$T/$s.obj" &&
        expect 0 "info $s" "$BIN" info "$T/$s.obj"
done

# ---- distance on a grid: exact along the edges through the corner ----
N=8
expect 0 "generate grid $N" "$BIN" generate grid $N -o "$T/g.obj"
grep '^v ' "$T/g.obj" >"$T/v.txt"
NV=$(wc -l <"$T/v.txt")
[ "$NV" -eq $(( (N + 1) * (N + 1) )) ] && ok "grid vertex count" || fail "grid has $NV vertices"
# The corner (0, 0): its 0-based index.
C=$(awk '$2 == 0 && $3 == 0 { print NR - 1; exit }' "$T/v.txt")
[ -n "$C" ] || fail "no corner vertex"

# axis_check DIST_FILE SCALE WHAT: d = SCALE * x on y = 0 and SCALE * y on
# x = 0, to 1e-12 (the march along a straight boundary edge is exact).
axis_check() {
    paste -d ' ' "$T/v.txt" "$1" | awk -v s="$2" '
        function abs(a) { return a < 0 ? -a : a }
        $3 == 0 { n++; e = abs($5 - s * $2); if (e > m) m = e }
        $2 == 0 { n++; e = abs($5 - s * $3); if (e > m) m = e }
        END { printf "%d %.3g\n", n, m; exit !(n == 2 * '"$((N + 1))"' && m <= 1e-12) }' >"$T/chk"
    if [ $? -eq 0 ]; then ok "$3: $(cat "$T/chk") (axis vertices, max error)"; else fail "$3: $(cat "$T/chk")"; fi
}
if expect 0 "distance grid -> txt" "$BIN" distance "$T/g.obj" --source "$C" -o "$T/d.txt"; then
    [ "$(wc -l <"$T/d.txt")" -eq "$NV" ] && ok "one value per vertex" || fail "line count"
    axis_check "$T/d.txt" 1 "grid distances along the axes"
    # Far corner (1, 1): FMM overestimates sqrt(2) a little, never underestimates much.
    far=$(paste -d ' ' "$T/v.txt" "$T/d.txt" | awk '$2 == 1 && $3 == 1 { print $5 }')
    awk -v d="$far" 'BEGIN { exit !(d >= 1.41421356237 - 1e-9 && d < 1.6) }' &&
        ok "far corner $far in [sqrt 2, 1.6)" || fail "far corner $far"
fi
# Uniform cost 2 (per vertex, text file) doubles every distance.
awk '{ print 2 }' "$T/v.txt" >"$T/cost.txt"
expect 0 "distance with --cost" "$BIN" distance "$T/g.obj" --source "$C" --cost "$T/cost.txt" -o "$T/d2.txt" &&
    axis_check "$T/d2.txt" 2 "cost 2 along the axes"
# The same cost as .npy, float64 and float32 (header padded to 64 bytes).
# npy_twos DESCR BYTES_OF_2.0 FILE: NV values of 2.0.
npy_twos() {
    dict="{'descr': '$1', 'fortran_order': False, 'shape': ($NV,), }"
    { printf '\223NUMPY\001\000\166\000'; printf "%-117s\n" "$dict"
      i=0; while [ $i -lt "$NV" ]; do printf "$2"; i=$((i + 1)); done; } >"$3"
}
npy_twos '<f8' '\0\0\0\0\0\0\0\100' "$T/cost8.npy"
npy_twos '<f4' '\0\0\0\100' "$T/cost4.npy"
for c in cost8 cost4; do
    expect 0 "distance with --cost $c.npy" "$BIN" distance "$T/g.obj" --source "$C" --cost "$T/$c.npy" -o "$T/d_$c.txt" &&
        axis_check "$T/d_$c.txt" 2 "$c.npy cost 2 along the axes"
done
head -c 100 "$T/cost8.npy" >"$T/cut.npy"
expect 1 "truncated cost .npy" "$BIN" distance "$T/g.obj" --source "$C" --cost "$T/cut.npy" -o "$T/x.txt"
# Per-face cost: nf values.
awk 'NR <= 2 * '"$N"' * '"$N"' { print 2 }' "$T/v.txt" "$T/v.txt" >"$T/fcost.txt"
expect 0 "distance with --cost-per-face" "$BIN" distance "$T/g.obj" --source "$C" --cost "$T/fcost.txt" --cost-per-face -o "$T/d3.txt" &&
    axis_check "$T/d3.txt" 2 "face cost 2 along the axes"
expect 1 "cost count mismatch" "$BIN" distance "$T/g.obj" --source "$C" --cost "$T/fcost.txt" -o "$T/d4.txt"
# --max-distance: vertices beyond it are inf, those well inside are kept.
if expect 0 "distance --max-distance" "$BIN" distance "$T/g.obj" --source "$C" --max-distance 0.3 -o "$T/dm.txt"; then
    paste -d ' ' "$T/v.txt" "$T/dm.txt" | awk '
        $3 == 0 && $2 >= 0.5 && $5 != "inf" { bad++ }
        $3 == 0 && $2 <= 0.25 && $5 + 0 != $2 + 0 { bad++ }
        END { exit bad > 0 }' && ok "max-distance cut-off" || fail "max-distance values"
fi
# Two sources: the opposite corner too; the middle of the bottom edge is 0.5.
C2=$(awk '$2 == 1 && $3 == 0 { print NR - 1; exit }' "$T/v.txt")
if expect 0 "distance two sources" "$BIN" distance "$T/g.obj" --source "$C" --source "$C2" -o "$T/dd.txt"; then
    paste -d ' ' "$T/v.txt" "$T/dd.txt" | awk '
        function abs(a) { return a < 0 ? -a : a }
        $3 == 0 { e = $2 < 0.5 ? $2 : 1 - $2; if (abs($5 - e) > 1e-12) bad++ }
        END { exit bad > 0 }' && ok "two sources along the bottom edge" || fail "two sources"
fi
# A face source at a vertex (barycentric 1 0 0) equals the vertex source.
FACE=$(grep '^f ' "$T/g.obj" | awk -v c=$((C + 1)) '$2 == c { print NR - 1; exit }')
if [ -n "$FACE" ] && expect 0 "distance --face-source" "$BIN" distance "$T/g.obj" --face-source "$FACE" 1 0 0 -o "$T/df.txt"; then
    axis_check "$T/df.txt" 1 "face source at the corner"
fi
expect 1 "source out of range" "$BIN" distance "$T/g.obj" --source 100000 -o "$T/x.txt"
expect 1 "bad barycentric" "$BIN" distance "$T/g.obj" --face-source 0 0.5 0.6 0 -o "$T/x.txt"
# .npy output: magic, 64-byte aligned header, nv float64 values.
if expect 0 "distance -> npy" "$BIN" distance "$T/g.obj" --source "$C" -o "$T/d.npy"; then
    size=$(wc -c <"$T/d.npy")
    [ "$size" -eq $((128 + 8 * NV)) ] && ok "npy size $size" || fail "npy size $size"
    [ "$(head -c 6 "$T/d.npy" | tail -c 5)" = "NUMPY" ] && ok "npy magic" || fail "npy magic"
    head -c 128 "$T/d.npy" | grep -q "'descr': '<f8', 'fortran_order': False, 'shape': ($NV,)" &&
        ok "npy header" || fail "npy header"
    [ ! -e "$T/d.npy.partial" ] && ok "no .partial left" || fail ".partial left"
fi
# An unwritable output: exit 1.
expect 1 "unwritable output" "$BIN" distance "$T/g.obj" --source "$C" -o "$T/no/such/dir/d.txt"

echo "$FAILS failure(s)"
[ "$FAILS" -eq 0 ]
