#!/usr/bin/env bash
# The installed C API as a program outside the project sees it: `cmake --install` of the build's
# deform_c component into a temporary prefix, then tests/client/c_api_consumer.c built twice from
# that prefix alone, with `cc` and pkg-config's flags (deform_c.pc), and as a CMake project using
# find_package(deform_c) (deform_cConfig.cmake, deform_c::deform_c); both run against a real
# deformd, and a third time from a plugin folder made by scripts/bundle-c-api.sh (every library
# but the C and C++ runtimes loaded from the folder). Also checks the installed files, the SONAME (libdeform_c.so.MAJOR) and
# that the package's version file refuses another major version.
# Usage: c_api_package_test.sh CMAKE BUILD_DIR DEFORMD SOURCE_DIR VERSION CC [C_FLAGS [CXX]]
# CC and C_FLAGS are the build's C compiler and CMAKE_C_FLAGS, none in a Release build: the
# compile line is then `cc` and pkg-config's flags alone. A sanitizer build's library needs its
# programs built with the same sanitizers and linked by the C++ driver CXX (UBSan's C++ runtime).
set -euo pipefail
cmake="$1"
build_dir="$2"
deformd="$3"
source_dir="$4"
version="$5"
cc="$6"
read -r -a c_flags <<<"${7:-}"
cxx="${8:-}"
major="${version%%.*}"
# shellcheck source=scripts/deformd-process.sh
source "$source_dir/scripts/deformd-process.sh"
deformd_make_work

# build_consumer OUTPUT [LINK_FLAG...]: tests/client/c_api_consumer.c with pkg-config's flags
# ($PKG_CONFIG_PATH), in one step with CC, or compiled by CC and linked by CXX.
build_consumer() {
  local output="$1"
  shift
  local source="$source_dir/tests/client/c_api_consumer.c"
  # shellcheck disable=SC2046  # pkg-config's flags are words
  if [ -z "$cxx" ]; then
    "$cc" "${c_flags[@]}" -o "$output" "$source" "$@" $(pkg-config --cflags --libs deform_c)
  else
    "$cc" "${c_flags[@]}" -c -o "$output.o" "$source" $(pkg-config --cflags deform_c) &&
      "$cxx" "${c_flags[@]}" -o "$output" "$output.o" "$@" $(pkg-config --libs deform_c)
  fi
}

fail() {
  echo "c_api_package_test: $*" >&2
  [ -f "$WORK/deformd.log" ] && sed 's/^/  deformd: /' "$WORK/deformd.log" >&2
  exit 1
}

prefix="$WORK/prefix"
"$cmake" --install "$build_dir" --component deform_c --prefix "$prefix" >"$WORK/install.log" ||
  fail "cmake --install failed: $(cat "$WORK/install.log")"
pc_file="$(find "$prefix" -name deform_c.pc)"
[ -n "$pc_file" ] || fail "no deform_c.pc installed"
libdir="$(dirname "$(dirname "$pc_file")")"
for file in include/deform_c.h "${libdir#"$prefix"/}/libdeform_c.so.$version"; do
  [ -f "$prefix/$file" ] || fail "not installed: $file"
done
[ "$(readlink "$libdir/libdeform_c.so.$major")" = "libdeform_c.so.$version" ] ||
  fail "libdeform_c.so.$major is not a link to libdeform_c.so.$version"
[ "$(readlink "$libdir/libdeform_c.so")" = "libdeform_c.so.$major" ] ||
  fail "libdeform_c.so is not a link to libdeform_c.so.$major"
soname="$(readelf -d "$libdir/libdeform_c.so.$version" | sed -n 's/.*(SONAME).*\[\(.*\)\]/\1/p')"
[ "$soname" = "libdeform_c.so.$major" ] || fail "SONAME is '$soname', not libdeform_c.so.$major"

# pkg-config alone: the compile line the docs give.
export PKG_CONFIG_PATH="$libdir/pkgconfig"
[ "$(pkg-config --modversion deform_c)" = "$version" ] || fail "pkg-config --modversion differs"
build_consumer "$WORK/consumer_pkgconfig" || fail "cc with pkg-config's flags failed"
# It loads the installed library (no rpath: LD_LIBRARY_PATH, as for any non-system prefix).
resolved="$(LD_LIBRARY_PATH="$libdir" ldd "$WORK/consumer_pkgconfig" |
  sed -n 's/.*libdeform_c\.so\.[0-9]* => \([^ ]*\).*/\1/p')"
[ "$resolved" = "$libdir/libdeform_c.so.$major" ] ||
  fail "the program would load '$resolved', not $libdir/libdeform_c.so.$major"

# A plugin folder (scripts/bundle-c-api.sh): the library with copies of its dependencies, which
# the loader takes from the folder, not from the system, through the library's $ORIGIN.
plugin="$WORK/plugin"
"$source_dir/scripts/bundle-c-api.sh" "$plugin" "$libdir/libdeform_c.so" >"$WORK/bundle.log" ||
  fail "bundle-c-api.sh failed: $(cat "$WORK/bundle.log")"
system='^(linux-vdso|ld-linux.*|libc|libm|libdl|libpthread|librt|libstdc\+\+|libgcc_s)\.so'
# A program shipped in the folder with it finds the library beside itself (its own $ORIGIN), and
# the library finds the rest; no LD_LIBRARY_PATH.
# shellcheck disable=SC2016  # $ORIGIN is the loader's
build_consumer "$plugin/consumer" -Wl,-rpath,'$ORIGIN' ||
  fail "cc of the plugin folder's program failed"
unset PKG_CONFIG_PATH
shipped=0
while read -r name path; do
  [[ "$name" =~ $system ]] && continue
  [ "$path" = "$plugin/$name" ] || fail "the plugin's library takes $name from $path"
  shipped=$((shipped + 1))
done < <(ldd "$plugin/consumer" | awk '/=>/ {print $1, $3}')
[ "$shipped" -gt 10 ] || fail "only $shipped libraries resolved in the plugin folder"

# CMake: find_package(deform_c VERSION) and the imported target, in a C-only project.
project="$WORK/cmake_consumer"
mkdir -p "$project"
cp "$source_dir/tests/client/c_api_consumer.c" "$project/"
cat >"$project/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.16)
project(consumer LANGUAGES C)
find_package(deform_c \${REQUIRED_VERSION} REQUIRED CONFIG)
add_executable(consumer c_api_consumer.c)
target_link_libraries(consumer PRIVATE deform_c::deform_c)
if(LINK_WITH_CXX)
  enable_language(CXX)
  set_target_properties(consumer PROPERTIES LINKER_LANGUAGE CXX)
endif()
CMAKE
cxx_options=()
[ -z "$cxx" ] || cxx_options=(-DLINK_WITH_CXX=ON -DCMAKE_CXX_COMPILER="$cxx")
"$cmake" -S "$project" -B "$project/build" -DCMAKE_PREFIX_PATH="$prefix" \
  -DCMAKE_C_COMPILER="$cc" -DCMAKE_C_FLAGS="${c_flags[*]}" \
  -DCMAKE_EXE_LINKER_FLAGS="${c_flags[*]}" "${cxx_options[@]}" -DREQUIRED_VERSION="$version" \
  >"$WORK/cmake.log" 2>&1 ||
  fail "configuring the find_package project failed: $(cat "$WORK/cmake.log")"
"$cmake" --build "$project/build" >"$WORK/cmake-build.log" 2>&1 ||
  fail "building the find_package project failed: $(cat "$WORK/cmake-build.log")"
if "$cmake" -S "$project" -B "$WORK/other_major" -DCMAKE_PREFIX_PATH="$prefix" \
  -DREQUIRED_VERSION="$((major + 1)).0" >"$WORK/other-major.log" 2>&1; then
  fail "find_package(deform_c $((major + 1)).0) accepted version $version"
fi
grep -q "version: $version" "$WORK/other-major.log" ||
  fail "find_package($((major + 1)).0) failed, but not on the version: $(cat "$WORK/other-major.log")"

# Both programs against a real deformd.
deformd_start "$WORK/deformd.log" "$deformd" --listen 127.0.0.1:0 --workers 2 ||
  fail "deformd did not start"
LD_LIBRARY_PATH="$libdir" "$WORK/consumer_pkgconfig" "$DEFORMD_ADDRESS" "$version" ||
  fail "the pkg-config build failed against deformd"
"$plugin/consumer" "$DEFORMD_ADDRESS" "$version" ||
  fail "the plugin folder's program failed against deformd"
# CMake's build tree carries an rpath to the imported library: no LD_LIBRARY_PATH.
"$project/build/consumer" "$DEFORMD_ADDRESS" "$version" ||
  fail "the find_package build failed against deformd"
echo "c_api_package_test: installed libdeform_c $version (SONAME $soname) built with pkg-config" \
  "and find_package, both streamed from deformd, and from a plugin folder of $shipped libraries"
