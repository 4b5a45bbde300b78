#!/usr/bin/env bash
# Installs the build into a temporary prefix (cmake --install), then builds
# the complete C program of docs/getting-started.md as another project would
# and runs it, checking the
# distances on the unit square (0, 1, 1, sqrt(2)):
#   - CMake find_package: meshfmm::meshfmm (shared) and meshfmm::meshfmm_static,
#     and a C++ translation unit that includes meshfmm.h;
#   - pkg-config: dynamic (the page's line, with -Wl,-rpath for the prefix)
#     and static (pkg-config --static, linked with -static);
# and that libmeshfmm.so does not depend on libOpenCL (it is dlopen'ed).
# Usage: run.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$1 build=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix="$tmp/prefix"
cmake --install "$build" --prefix "$prefix" >/dev/null
mkdir -p "$tmp/consumer"
cp "$src/tests/consumer/CMakeLists.txt" "$src/tests/consumer/cxx_example.cpp" "$tmp/consumer/"
# the first ```c block of the getting-started page (a complete program)
awk '/^```c$/ {on = 1; next} /^```$/ && on {exit} on' "$src/docs/getting-started.md" > "$tmp/consumer/readme_example.c"
test -s "$tmp/consumer/readme_example.c"
fail() { echo "consumer: $*" >&2; exit 1; }
expected="0 0.000000000000
1 1.000000000000
2 1.000000000000
3 1.414213562373"
check() { # NAME COMMAND...: runs it and compares its output
    local name=$1; shift
    local out
    out=$("$@") || fail "$name exited with $?"
    [ "$out" = "$expected" ] || { echo "$name printed:"; echo "$out"; fail "$name: wrong distances"; }
}

lib=$(find "$prefix" -name 'libmeshfmm.so' | head -1)
[ -n "$lib" ] || fail "no libmeshfmm.so installed"
libdir=$(dirname "$lib")
[ -f "$libdir/libmeshfmm.a" ] || fail "no libmeshfmm.a beside libmeshfmm.so"
if command -v readelf >/dev/null; then
    readelf -d "$lib" | grep -qi 'NEEDED.*libOpenCL' && fail "libmeshfmm.so links libOpenCL"
fi
ldd "$lib" | grep -qi libOpenCL && fail "ldd libmeshfmm.so lists libOpenCL"

# CMake: shared, static, C++
cmake -S "$tmp/consumer" -B "$tmp/consumer/build" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$tmp/consumer/build" >/dev/null
check "find_package, meshfmm::meshfmm" env LD_LIBRARY_PATH="$libdir" "$tmp/consumer/build/readme_example"
check "find_package, meshfmm::meshfmm_static" "$tmp/consumer/build/readme_example_static"
ldd "$tmp/consumer/build/readme_example_static" | grep -q libmeshfmm \
    && fail "the static consumer needs libmeshfmm.so"
check "C++ consumer" env LD_LIBRARY_PATH="$libdir" "$tmp/consumer/build/cxx_example"

# pkg-config for a non-system prefix, as the page says
export PKG_CONFIG_PATH="$libdir/pkgconfig"
cc -std=c99 -Wall -Wextra -Werror "$tmp/consumer/readme_example.c" -o "$tmp/pc_dynamic" \
   $(pkg-config --cflags --libs meshfmm) -Wl,-rpath,"$libdir"
check "pkg-config (shared, rpath)" "$tmp/pc_dynamic"
cc -std=c99 -Wall -Wextra -Werror "$tmp/consumer/readme_example.c" -o "$tmp/pc_static" -static \
   $(pkg-config --static --cflags --libs meshfmm) 2> "$tmp/static_link.txt" \
    || { cat "$tmp/static_link.txt"; fail "pkg-config --static link failed"; }
check "pkg-config --static (-static)" "$tmp/pc_static"
echo "consumer: find_package (shared, static, C++) and pkg-config (shared, static) builds print the exact distances; libmeshfmm.so does not link libOpenCL"
