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
for c in info distance generate path allpairs landmarks voronoi weld; do
    expect 0 "$c --help" "$BIN" "$c" --help && grep -q "usage: meshfmm $c" "$T/out" ||
        fail "$c --help text"
done
expect 2 "no command" "$BIN"
expect 2 "unknown command" "$BIN" frobnicate
# the Python package's commands: listed, and named when given here
"$BIN" --help | grep -q '^  render ' && "$BIN" --help | grep -q '^  isolines ' &&
    "$BIN" --help | grep -q 'python -m meshfmm' && ok "--help lists the python commands" ||
    fail "--help lacks the python commands"
for c in render isolines; do
    expect 2 "$c (a python command)" "$BIN" "$c" x.obj -o x.png &&
        grep -q "python -m meshfmm $c" "$T/err" || fail "$c: no pointer to python -m meshfmm"
done
expect 2 "voronoi without a source" "$BIN" voronoi "$DATA/meshes/hand_lowres.obj" -o "$T/l.npy"
expect 2 "voronoi --distances with a bad extension" "$BIN" voronoi "$DATA/meshes/hand_lowres.obj" --source 0 --distances "$T/d.csv" -o "$T/l.npy"
expect 2 "voronoi --distances twice" "$BIN" voronoi "$DATA/meshes/hand_lowres.obj" --source 0 --distances "$T/d.npy" --distances "$T/e.npy" -o "$T/l.npy"
expect 1 "distance --weld source out of range" "$BIN" distance "$DATA/meshes/hand_lowres.obj" --weld --source 810 -o "$T/d.txt" &&
    grep -q "vertex 810 is outside \[0, 810)" "$T/err" || fail "--weld range message: $(cat "$T/err")"
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
# a copied face is counted, and is no wall: vertex 3 of the unit square is
# sqrt(2) from vertex 0 (it was 2: the copy made the diagonal non-manifold)
printf 'v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nf 3 4 2\n' >"$T/copy.obj"
expect 0 "info copied face" "$BIN" info "$T/copy.obj" &&
    { [ "$(value "duplicate faces" "$T/out")" = 1 ] && [ "$(value "non-manifold edges" "$T/out")" = 0 ] &&
      ok "copied face counted" || fail "copied face counts: $(cat "$T/out")"; }
for opt in "" --exact; do
    expect 0 "distance copied face $opt" "$BIN" distance "$T/copy.obj" --source 0 $opt -o "$T/copy.txt" &&
        { awk 'NR == 4 { exit !($1 > 1.41421356237309 && $1 < 1.4142135623731) }' "$T/copy.txt" &&
          ok "copied face: d(3) = sqrt 2 $opt" || fail "copied face $opt: $(cat "$T/copy.txt")"; }
done

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
[ ! -e "$T/bad.txt" ] && ! ls "$T" | grep -q '^bad.txt.' && ok "no output after a failure" ||
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
# (the plain start: along the axes the march adds up h exactly, which this compares bit for bit)
if expect 0 "distance --max-distance" "$BIN" distance "$T/g.obj" --source "$C" --max-distance 0.3 --plain-start -o "$T/dm.txt"; then
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
    ls "$T" | grep -q '^d.npy.' && fail "temporary file left" || ok "no temporary file left"
fi
# An unwritable output: exit 1.
expect 1 "unwritable output" "$BIN" distance "$T/g.obj" --source "$C" -o "$T/no/such/dir/d.txt"

# ---- getopt_long conventions: --opt=value, -o -, options in any order, --help ----
if expect 0 "distance --source=C --output=FILE" "$BIN" distance "$T/g.obj" --source="$C" --output="$T/eq.txt"; then
    cmp -s "$T/eq.txt" "$T/d.txt" && ok "--source=C equals --source C" || fail "--source=C differs"
fi
if expect 0 "distance -o - (stdout)" "$BIN" distance "$T/g.obj" --source "$C" -o -; then
    cmp -s "$T/out" "$T/d.txt" && ok "-o - writes the .txt to stdout" || fail "-o - output differs"
fi
expect 0 "options after the mesh, mesh last" "$BIN" distance --source "$C" -o "$T/perm.txt" "$T/g.obj" &&
    { cmp -s "$T/perm.txt" "$T/d.txt" && ok "argument order free" || fail "permuted args differ"; }
expect 0 "path -o - (csv to stdout)" "$BIN" path "$T/g.obj" --source "$C" --target="$C2" -o - &&
    { head -1 "$T/out" | grep -q '^face,b0,b1,b2,x,y,z$' && [ "$(grep -c '' "$T/err")" -eq 1 ] &&
      awk -F, 'NR > 1 && NF != 7 { bad++ } END { exit bad > 0 || NR < 3 }' "$T/out" &&
      ok "path csv on stdout, length on stderr ($(cat "$T/err"))" || fail "path -o -: $(cat "$T/out" "$T/err")"; }
expect 0 "path --face-source with negative-looking weights" "$BIN" path "$T/g.obj" --face-source "$FACE" 1 0 0 --target "$C2" -o "$T/p.obj" &&
    { grep -q '^l 1 2' "$T/p.obj" && ok "path .obj polyline" || fail "path .obj"; }
expect 2 "distance --face-source missing weights" "$BIN" distance "$T/g.obj" --face-source 0 1 -o "$T/x.txt"
expect 2 "option without its value" "$BIN" distance "$T/g.obj" --source
expect 2 "unknown long option" "$BIN" distance "$T/g.obj" --source 0 --frobnicate -o "$T/x.txt"
expect 2 "allpairs -o - refused" "$BIN" allpairs "$T/g.obj" -o -
expect 0 "generate -o -" "$BIN" generate grid 2 -o - && { grep -c '^v ' "$T/out" | grep -qx 9 && ok "generate to stdout" || fail "generate stdout"; }

# ---- allpairs --cost equals distance --cost; --threads 0 and bad counts ----
# A single-source allpairs row equals `distance` with the same cost, bit for bit.
echo "$C" >"$T/one.txt"
if expect 0 "allpairs --cost --threads 0" "$BIN" allpairs "$T/g.obj" --sources "$T/one.txt" --cost "$T/fcost.txt" --cost-per-face --dtype float64 --threads 0 --backend threads -o "$T/ap.npy"; then
    expect 0 "distance --cost (npy)" "$BIN" distance "$T/g.obj" --source "$C" --cost "$T/fcost.txt" --cost-per-face -o "$T/dc.npy"
    tail -c +129 "$T/ap.npy" >"$T/ap.bin"; tail -c +129 "$T/dc.npy" >"$T/dc.bin"
    cmp -s "$T/ap.bin" "$T/dc.bin" && [ -s "$T/ap.bin" ] && ok "allpairs --cost row == distance --cost" ||
        fail "allpairs --cost row differs"
fi
expect 1 "allpairs cost count mismatch" "$BIN" allpairs "$T/g.obj" --sources "$T/one.txt" --cost "$T/fcost.txt" -o "$T/x.npy"
expect 2 "allpairs --threads -1" "$BIN" allpairs "$T/g.obj" --threads -1 -o "$T/x.npy"

# ---- outputs: unique temporary, exclusive create, rename ----
# A symlink planted at the predictable name OUT.partial is not followed.
echo "precious" >"$T/victim"
ln -s "$T/victim" "$T/sym.txt.partial"
expect 0 "distance beside a planted symlink" "$BIN" distance "$T/g.obj" --source "$C" -o "$T/sym.txt" &&
    { [ "$(cat "$T/victim")" = precious ] && cmp -s "$T/sym.txt" "$T/d.txt" &&
      ok "planted symlink not followed" || fail "the symlink was followed"; }
# Two concurrent runs to one target: one complete, valid file, no temporaries.
"$BIN" generate sphere 5 -o "$T/big.obj" >/dev/null 2>&1
"$BIN" distance "$T/big.obj" --source 0 -o "$T/ref.txt" 2>/dev/null
"$BIN" distance "$T/big.obj" --source 0 -o "$T/race.txt" 2>"$T/err1" & p1=$!
"$BIN" distance "$T/big.obj" --source 0 -o "$T/race.txt" 2>"$T/err2" & p2=$!
wait $p1; r1=$?; wait $p2; r2=$?
[ $r1 -eq 0 ] && [ $r2 -eq 0 ] && cmp -s "$T/race.txt" "$T/ref.txt" && ! ls "$T" | grep -q '^race.txt.' &&
    ok "two concurrent runs: one complete file" || fail "concurrent runs: $r1 $r2 $(cat "$T/err1" "$T/err2")"
# SIGTERM during a write leaves neither the target nor a temporary.
"$BIN" allpairs "$T/big.obj" -o "$T/sig.npy" --backend threads --threads 1 --quiet 2>/dev/null & p=$!
i=0; while ! ls "$T" | grep -q '^sig.npy.' && [ $i -lt 100 ]; do sleep 0.05; i=$((i + 1)); done
kill -TERM $p; wait $p; r=$?
[ $r -eq 130 ] && [ ! -e "$T/sig.npy" ] && ! ls "$T" | grep -q '^sig.npy.' && ok "SIGTERM: exit 130, nothing left" ||
    fail "SIGTERM: exit $r, left: $(ls "$T" | grep sig)"

# A target name of 250 characters (NAME_MAX 255): its temporary's name is
# cut to fit, so that mkstemp does not fail with "File name too long".
long=$(printf 'l%.0s' $(seq 246)).txt
expect 0 "distance -o a 250-character name" "$BIN" distance "$T/g.obj" --source "$C" -o "$T/$long" &&
    { cmp -s "$T/$long" "$T/d.txt" && ! ls "$T" | grep -q '^lll.*\.......$' && ok "long name: complete, no temporary" ||
      fail "long name: $(ls "$T" | grep '^lll')"; }

# ---- --method windows: the flat grid's Euclidean distances; its usage errors ----
if expect 0 "distance --method windows" "$BIN" distance "$T/g.obj" --source "$C" --method windows -o "$T/w.txt"; then
    paste -d ' ' "$T/v.txt" "$T/w.txt" | awk '
        function abs(a) { return a < 0 ? -a : a }
        { n++; e = abs($5 - sqrt($2 * $2 + $3 * $3)); if (e > m) m = e }
        END { printf "%d %.3g\n", n, m; exit !(n == '"$NV"' && m <= 1e-12) }' >"$T/chk" &&
        ok "windows on the grid is Euclidean: $(cat "$T/chk")" || fail "windows on the grid: $(cat "$T/chk")"
fi
expect 0 "landmarks --method windows" "$BIN" landmarks "$T/g.obj" -k 3 --method windows -o "$T/lw.txt"
expect 0 "allpairs --method windows" "$BIN" allpairs "$T/g.obj" --method windows --quiet -o "$T/aw.npy"
expect 2 "distance --exact with --method" "$BIN" distance "$T/g.obj" --source "$C" --exact --method windows -o "$T/x.txt" &&
    { grep -q -- "--exact and --method are two methods" "$T/err" && ok "--exact --method message" || fail "message: $(cat "$T/err")"; }
# a constant cost 2: twice the Euclidean distances
if expect 0 "distance --method windows with --cost" "$BIN" distance "$T/g.obj" --source "$C" --method windows --cost "$T/cost.txt" -o "$T/wc.txt"; then
    paste -d ' ' "$T/v.txt" "$T/wc.txt" | awk '
        function abs(a) { return a < 0 ? -a : a }
        { n++; e = abs($5 - 2 * sqrt($2 * $2 + $3 * $3)); if (e > m) m = e }
        END { printf "%d %.3g\n", n, m; exit !(n == '"$NV"' && m <= 2e-12) }' >"$T/chk" &&
        ok "windows with cost 2 on the grid is twice Euclidean: $(cat "$T/chk")" || fail "windows with cost 2: $(cat "$T/chk")"
fi
expect 2 "voronoi --method exact" "$BIN" voronoi "$T/g.obj" --source "$C" --method exact -o "$T/x.txt"
[ ! -e "$T/x.txt" ] && [ ! -e "$T/x.npy" ] && ok "refused --method runs write nothing" || fail "a refused run wrote"
# the window method on OpenCL: the rows of the CPU backends, byte for byte
if "$BIN" allpairs "$T/g.obj" --method windows --backend opencl --quiet -o "$T/awcl.npy" 2>"$T/err"; then
    cmp -s "$T/aw.npy" "$T/awcl.npy" && ok "allpairs --method windows on opencl = threads" ||
        fail "allpairs --method windows on opencl differs from threads"
elif grep -q "OpenCL" "$T/err"; then
    ok "allpairs --method windows --backend opencl: no OpenCL device here ($(head -c 80 "$T/err"))"
else
    fail "allpairs --method windows --backend opencl: $(cat "$T/err")"
fi

# ---- options that conflict are refused, not resolved by the last one ----
expect 2 "--plain-start with --exact-start-radius" "$BIN" distance "$T/g.obj" --source "$C" --plain-start --exact-start-radius 3 -o "$T/x.txt"
expect 2 "allpairs --exact-start-radius with --plain-start" "$BIN" allpairs "$T/g.obj" --exact-start-radius 3 --plain-start -o "$T/x.npy"
expect 2 "distance --exact with --exact-start-radius" "$BIN" distance "$T/g.obj" --source "$C" --exact --exact-start-radius 2 -o "$T/x.txt"
expect 2 "path with two targets" "$BIN" path "$T/g.obj" --source "$C" --target "$C2" --target-face 0 0.2 0.3 0.5 -o "$T/x.csv"
expect 2 "allpairs --source (not an abbreviation of --sources)" "$BIN" allpairs "$T/g.obj" --source 3 -o "$T/x.npy" &&
    { grep -q "meshfmm distance --source 3" "$T/err" && ok "allpairs --source message" || fail "message: $(cat "$T/err")"; }
expect 2 "allpairs --sources twice" "$BIN" allpairs "$T/g.obj" --sources "$T/one.txt" --sources "$T/one.txt" -o "$T/x.npy"
# a value option given twice: getopt_long would let the last win silently
expect 2 "allpairs -o twice" "$BIN" allpairs "$T/g.obj" -o "$T/x.npy" --output "$T/y.npy" &&
    { grep -q -- "-o/--output given twice" "$T/err" && ok "-o twice message" || fail "message: $(cat "$T/err")"; }
expect 2 "distance --max-distance twice" "$BIN" distance "$T/g.obj" --source "$C" --max-distance 1 --max-distance 2 -o "$T/x.txt"
expect 2 "distance --exact-start-radius twice" "$BIN" distance "$T/g.obj" --source "$C" --exact-start-radius 1 --exact-start-radius 2 -o "$T/x.txt"
expect 2 "path --cost twice" "$BIN" path "$T/g.obj" --source "$C" --target "$C2" --cost "$T/cost.txt" --cost "$T/cost.txt" -o "$T/x.csv"
expect 2 "path --max-points twice" "$BIN" path "$T/g.obj" --source "$C" --target "$C2" --max-points 9 --max-points 10 -o "$T/x.csv"
expect 2 "generate -o twice" "$BIN" generate grid 4 -o "$T/x.obj" -o "$T/y.obj"
expect 2 "info --max-unfold-steps twice" "$BIN" info "$T/g.obj" --max-unfold-steps 3 --max-unfold-steps 4
expect 2 "allpairs --backend twice" "$BIN" allpairs "$T/g.obj" --backend serial --backend threads -o "$T/x.npy"
expect 0 "distance --source twice (several sources)" "$BIN" distance "$T/g.obj" --source "$C" --source "$C2" -o "$T/two.txt"
# --threads sizes the threads backend only
expect 2 "allpairs --threads with --backend serial" "$BIN" allpairs "$T/g.obj" --threads 2 --backend serial -o "$T/x.npy"
expect 2 "allpairs --threads with --backend opencl" "$BIN" allpairs "$T/g.obj" --backend opencl --threads 1 -o "$T/x.npy"
expect 2 "generate grid --stretch" "$BIN" generate grid 4 --stretch 2 -o "$T/x.obj"
expect 2 "generate sphere --radii" "$BIN" generate sphere 1 --radii 3 1 -o "$T/x.obj"
[ ! -e "$T/x.txt" ] && [ ! -e "$T/x.npy" ] && [ ! -e "$T/x.obj" ] && [ ! -e "$T/y.npy" ] &&
    [ ! -e "$T/y.obj" ] && [ ! -e "$T/x.csv" ] && ok "no output from refused runs" || fail "a refused run wrote"
# path's length is its result on stdout: a full stdout is a failure
if [ -w /dev/full ]; then
    expect 1 "path with stdout full" sh -c '"$1" path "$2" --source "$3" --target "$4" -o "$5" >/dev/full' sh "$BIN" "$T/g.obj" "$C" "$C2" "$T/p.csv"
fi

# ---- an output that is an input (any spelling, hard link) is refused ----
cp "$T/g.obj" "$T/in.obj"; cp "$T/cost.txt" "$T/incost.txt"
ln "$T/in.obj" "$T/hard.txt"
mkdir -p "$T/sub"
expect 2 "distance -o hard link to the mesh" "$BIN" distance "$T/in.obj" --source "$C" -o "$T/hard.txt"
expect 2 "path -o MESH (different spelling)" "$BIN" path "$T/in.obj" --source "$C" --target "$C2" -o "$T/sub/../in.obj"
ln "$T/incost.txt" "$T/costlink.txt"
expect 2 "output hard-linked to --cost" "$BIN" distance "$T/in.obj" --source "$C" --cost "$T/incost.txt" -o "$T/costlink.txt"
ln "$T/one.txt" "$T/srclink.npy"
expect 2 "allpairs output hard-linked to --sources" "$BIN" allpairs "$T/in.obj" --sources "$T/one.txt" -o "$T/srclink.npy"
ln "$T/in.obj" "$T/meshlink.npy"
expect 2 "allpairs output hard-linked to the mesh" "$BIN" allpairs "$T/in.obj" -o "$T/meshlink.npy"
cmp -s "$T/in.obj" "$T/g.obj" && cmp -s "$T/incost.txt" "$T/cost.txt" && ok "inputs untouched" || fail "an input was overwritten"

# ---- not regular files: refused at once, with the path ----
mkfifo "$T/fifo.obj" "$T/fifo.txt"
for m in /dev/zero "$T/fifo.obj" "$T/sub"; do
    expect 1 "info $m refused" timeout 20 "$BIN" info "$m" &&
        { grep -q "$m" "$T/err" && grep -Eq 'device|FIFO|directory' "$T/err" && ok "message: $(cat "$T/err")" ||
          fail "message: $(cat "$T/err")"; }
done
expect 1 "--cost /dev/zero refused" timeout 20 "$BIN" distance "$T/g.obj" --source 0 --cost /dev/zero -o "$T/x.txt"
expect 1 "--cost FIFO refused" timeout 20 "$BIN" distance "$T/g.obj" --source 0 --cost "$T/fifo.txt" -o "$T/x.txt"
expect 1 "--sources FIFO refused" timeout 20 "$BIN" allpairs "$T/g.obj" --sources "$T/fifo.txt" -o "$T/x.npy"
expect 1 "--sources /dev/zero (.npy) refused" timeout 20 "$BIN" allpairs "$T/g.obj" --sources /dev/zero -o "$T/x.npy"

# ---- .npy --sources: truncated and malformed headers are refused ----
# npy_file FILE HLEN DICT [DATA]: a version-1 .npy with a declared header length.
npy_file() { { printf '\223NUMPY\001\000'; printf "\\$(printf %o $(($2 % 256)))\\$(printf %o $(($2 / 256)))"; printf '%s' "$3"; printf "${4:-}"; } >"$1"; }
# 36 bytes, the header length promising more than the file: refused without
# reading past the buffer.
npy_file "$T/s36.npy" 26 "{'shape': (1,), 'descr': '"
[ "$(wc -c <"$T/s36.npy")" -eq 36 ] || fail "s36.npy is not 36 bytes"
expect 1 "36-byte --sources .npy" "$BIN" allpairs "$T/g.obj" --sources "$T/s36.npy" -o "$T/x.npy"
npy_file "$T/s36b.npy" 40 "{'descr': '<i"
expect 1 "truncated header --sources .npy" "$BIN" allpairs "$T/g.obj" --sources "$T/s36b.npy" -o "$T/x.npy"
# 128 bytes claiming 1e9 int32 values: refused before allocating 4 GB.
d="{'descr': '<i4', 'fortran_order': False, 'shape': (1100000000,), }"
npy_file "$T/s128.npy" 118 "$(printf '%-117s' "$d")
"
[ "$(wc -c <"$T/s128.npy")" -eq 128 ] || fail "s128.npy is $(wc -c <"$T/s128.npy") bytes"
expect 1 "128-byte --sources claiming 1.1e9 ids" "$BIN" allpairs "$T/g.obj" --sources "$T/s128.npy" -o "$T/x.npy" &&
    { grep -q "needs more bytes" "$T/err" && ok "size checked first" || fail "message: $(cat "$T/err")"; }
# A 2-D (3, 3) integer array is refused, not taken as 3 sources.
d="{'descr': '<i4', 'fortran_order': False, 'shape': (3, 3), }"
npy_file "$T/s33.npy" 118 "$(printf '%-117s' "$d")
" '\0\0\0\0\1\0\0\0\2\0\0\0\3\0\0\0\4\0\0\0\5\0\0\0\6\0\0\0\7\0\0\0\10\0\0\0'
expect 1 "(3, 3) --sources refused" "$BIN" allpairs "$T/g.obj" --sources "$T/s33.npy" -o "$T/x.npy" &&
    { grep -q "1-D" "$T/err" && grep -q "(3, 3)" "$T/err" && ok "2-D message" || fail "message: $(cat "$T/err")"; }
d="{'descr': '<i4', 'fortran_order': False, 'shape': (3,), }"
npy_file "$T/s3.npy" 118 "$(printf '%-117s' "$d")
" "\\0\\0\\0\\0\\$(printf %o "$C")\\0\\0\\0\\2\\0\\0\\0"
expect 0 "a valid (3,) --sources" "$BIN" allpairs "$T/g.obj" --sources "$T/s3.npy" -o "$T/ok3.npy"

# ---- STL is read; unsupported formats are refused, naming those read ----
awk 'BEGIN { print "solid g" } /^v / { v[++n] = $2 " " $3 " " $4 }
     /^f / { print "facet normal 0 0 1\nouter loop"; for (i = 2; i <= 4; i++) print "vertex " v[$i]
             print "endloop\nendfacet" } END { print "endsolid g" }' "$T/g.obj" >"$T/g.stl"
if expect 0 "distance on an ascii STL" "$BIN" distance "$T/g.stl" --source 0 -o "$T/stl.txt"; then
    [ "$(wc -l <"$T/stl.txt")" -eq "$NV" ] && ok "STL welded to $NV vertices" || fail "STL vertex count"
fi
printf '{"asset": {"version": "2.0"}}' >"$T/m.gltf"
expect 1 "glTF refused" "$BIN" info "$T/m.gltf" &&
    { grep -q "OBJ, OFF, PLY (ascii and binary) and STL" "$T/err" && ok "names the formats read" ||
      fail "message: $(cat "$T/err")"; }

echo "$FAILS failure(s)"
[ "$FAILS" -eq 0 ]
