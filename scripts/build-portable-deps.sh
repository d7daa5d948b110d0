#!/usr/bin/env bash
# Builds the static, position-independent dependencies of the portable libdwivedi.so.1 (the one the
# Blender packages carry, issue 16) from Debian 12's source packages, into a cache outside the
# clone, and prints the prefix on the last line of stdout:
#
#   prefix=$(bash scripts/build-portable-deps.sh | tail -n 1)
#   cmake -S . -B build -DDWV_PORTABLE_DEPS="$prefix"
#
# The cache is ${DWV_DEPS_CACHE:-/var/cache/dwivedi/portable-deps}/<hash of this script>/prefix;
# when it is complete the script only prints it (editing the script makes a new one). A run that
# stops half way resumes at the dependency it stopped in. No standard input is read; apt-get runs
# as root or through sudo. Each dependency's build time is printed, and kept in the cache's
# timings.txt (the cold figures, printed again on every warm run).
#
#   --print-prefix   print the prefix the current script would use and exit (builds nothing)
#
# What is built, with only the features libdwivedi uses (see cmake/portable.cmake for the link):
#   zlib 1.2.13 (+ its contrib/minizip, for Assimp's unzip), libpng 1.6.39, expat 2.5.0,
#   yaml-cpp 0.7.0, pystring 1.1.4, Imath 3.1.6, OpenEXRCore 3.1.5 (the C core library only),
#   OpenColorIO 2.1.3 (no apps, python, docs, tests), cJSON 1.7.15, Assimp 5.2.5 (OBJ and PLY
#   importers only, no exporters), Embree 3.13.5 (static, internal tasking: no TBB; SSE2,
#   AVX, AVX2 and AVX-512 kernels; triangles and instances only; filter functions and ray masks on).
# Sources: `apt-get source` from bookworm's deb-src (added below when missing), unpacked with
# dpkg-source so that Debian's patches apply. Where the archive this machine uses lacks a file of a
# bookworm source package (Embree's and pystring's debian.tar.xz, both files of OpenColorIO
# 2.1.2+dfsg1-4), the upstream .orig tarball is used as Debian ships it, and OpenColorIO comes
# from trixie's 2.1.3+dfsg orig tarball (the next patch release of 2.1, same ABI), fetched from
# the Debian pool by apt's own downloader and checked against the SHA-256 written below.
set -euo pipefail

script_path=$(readlink -f "${BASH_SOURCE[0]}")
script_hash=$(sha256sum "$script_path" | cut -c1-16)
cache_root=${DWV_DEPS_CACHE:-/var/cache/dwivedi/portable-deps}
cache=$cache_root/$script_hash
prefix=$cache/prefix
jobs=${DWV_DEPS_JOBS:-$(nproc)}

if [ "${1:-}" = "--print-prefix" ]; then echo "$prefix"; exit 0; fi
if [ $# -gt 0 ]; then echo "build-portable-deps: unknown argument '$1' (only --print-prefix)" >&2; exit 2; fi

say() { echo "build-portable-deps: $*" >&2; }
die() { say "error: $*"; exit 1; }

if [ -f "$prefix/.complete" ]; then
  say "reusing $prefix (complete; cold build times were:)"
  sed 's/^/  /' "$cache/timings.txt" >&2 || true
  echo "$prefix"
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then as_root=(); else as_root=(sudo -n); fi
mkdir -p "$cache_root" 2>/dev/null || "${as_root[@]}" install -d -m 0755 -o "$(id -u)" -g "$(id -g)" "$cache_root" \
  || die "cannot create $cache_root (set DWV_DEPS_CACHE to a writable folder)"
mkdir -p "$cache" || die "cannot create $cache"
exec 9>"$cache/.lock"
flock -w 7200 9 || die "another build holds $cache/.lock"
if [ -f "$prefix/.complete" ]; then echo "$prefix"; exit 0; fi   # built while we waited

total_start=$(date +%s)

# ---- packages: the tool chain, header-only utfcpp (Assimp's UTF-8), and bookworm's deb-src -------
packages=(build-essential cmake pkg-config dpkg-dev xz-utils bzip2 libutfcpp-dev apt)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
need_update=0
if ! grep -rqsE '^(Types: *deb-src|deb-src )' /etc/apt/sources.list /etc/apt/sources.list.d/ \
   || ! apt-cache showsrc embree 2>/dev/null | grep -q '^Version: 3\.13\.5'; then
  say "adding bookworm's deb-src to apt (/etc/apt/sources.list.d/dwivedi-src.sources)"
  printf '%s\n' 'Types: deb-src' 'URIs: http://deb.debian.org/debian' 'Suites: bookworm bookworm-updates' \
    'Components: main' 'Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg' \
    | "${as_root[@]}" tee /etc/apt/sources.list.d/dwivedi-src.sources >/dev/null
  need_update=1
fi
if [ ${#missing[@]} -gt 0 ] || [ $need_update -eq 1 ]; then
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update -q </dev/null >&2
fi
if [ ${#missing[@]} -gt 0 ]; then
  say "installing ${missing[*]}"
  "${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}" </dev/null >&2
fi

src=$cache/src
build=$cache/build
stamps=$cache/stamps
mkdir -p "$src/dl" "$build" "$stamps" "$prefix/lib" "$prefix/include"
: > "$cache/timings.txt.partial"
[ -f "$cache/timings.txt.done" ] || : > "$cache/timings.txt.done"

# ---- sources ---------------------------------------------------------------------------------------
# name  source-package  version  orig tarball  (full|orig: whether Debian's patches are applied)
sources=(
  "zlib       zlib        1:1.2.13.dfsg-1      zlib_1.2.13.dfsg.orig.tar.bz2         full"
  "libpng     libpng1.6   1.6.39-2+deb12u5     libpng1.6_1.6.39.orig.tar.gz          full"
  "expat      expat       2.5.0-1+deb12u2      expat_2.5.0.orig.tar.gz               full"
  "yaml-cpp   yaml-cpp    0.7.0+dfsg-8         yaml-cpp_0.7.0+dfsg.orig.tar.xz       full"
  "pystring   pystring    1.1.4-1              pystring_1.1.4.orig.tar.gz            orig"
  "imath      imath       3.1.6-1              imath_3.1.6.orig.tar.gz               full"
  "openexr    openexr     3.1.5-5              openexr_3.1.5.orig.tar.gz             full"
  "cjson      cjson       1.7.15-1+deb12u4     cjson_1.7.15.orig.tar.gz              full"
  "assimp     assimp      5.2.5~ds0-1          assimp_5.2.5~ds0.orig.tar.xz          full"
  "embree     embree      3.13.5+dfsg-2        embree_3.13.5+dfsg.orig.tar.xz        orig"
)
ocio_orig=opencolorio_2.1.3+dfsg.orig.tar.xz
ocio_url=http://deb.debian.org/debian/pool/main/o/opencolorio/$ocio_orig
ocio_sha256=516420206151e76b5515f5ae7e976c97a9920b13dbfb50ceada1dc4bd67116de

unpacked() { echo "$src/$1"; }

fetch_sources() {
  [ -f "$stamps/sources" ] && return 0
  local t0; t0=$(date +%s)
  cd "$src/dl"
  local line name pkg ver orig mode
  for line in "${sources[@]}"; do
    read -r name pkg ver orig mode <<<"$line"
    if [ ! -f "$orig" ] || { [ "$mode" = full ] && ! ls "${pkg}_${ver#*:}".debian.tar.* >/dev/null 2>&1; }; then
      # apt-get verifies every file it fetches against the signed Sources index; a missing
      # debian.tar.xz is fatal only where Debian's patches are wanted (mode full).
      apt-get source -q --download-only "$pkg=$ver" </dev/null >&2 || true
    fi
    [ -f "$orig" ] || die "$pkg $ver: apt-get source did not fetch $orig (is bookworm's deb-src in apt's sources?)"
    if [ "$mode" = full ]; then
      ls "${pkg}_${ver#*:}".debian.tar.* >/dev/null 2>&1 || die "$pkg $ver: the archive gave no debian.tar.* for it"
    fi
    rm -rf "$src/$name" "$src/$name.tmp"
    if [ "$mode" = full ]; then
      dpkg-source -x "${pkg}_${ver#*:}.dsc" "$src/$name.tmp" >/dev/null
    else
      mkdir "$src/$name.tmp"; tar -xf "$orig" -C "$src/$name.tmp" --strip-components=1
    fi
    mv "$src/$name.tmp" "$src/$name"
  done
  if [ ! -f "$ocio_orig" ] || ! echo "$ocio_sha256  $ocio_orig" | sha256sum -c --quiet - 2>/dev/null; then
    rm -f "$ocio_orig"
    /usr/lib/apt/apt-helper download-file "$ocio_url" "$src/dl/$ocio_orig" "SHA256:$ocio_sha256" </dev/null >&2 \
      || die "could not fetch $ocio_url"
  fi
  echo "$ocio_sha256  $ocio_orig" | sha256sum -c --quiet - || die "$ocio_orig: SHA-256 mismatch"
  rm -rf "$src/ocio"; mkdir "$src/ocio"; tar -xf "$ocio_orig" -C "$src/ocio" --strip-components=1
  echo "sources $(( $(date +%s) - t0 )) s" >> "$cache/timings.txt.done"
  say "sources: $(( $(date +%s) - t0 )) s"
  touch "$stamps/sources"
}

# Flags for every dependency: position-independent (it goes into a shared library), sections per
# function so that the final link can drop what libdwivedi never calls, and -O2 -DNDEBUG.
export CFLAGS="-O2 -fPIC -ffunction-sections -fdata-sections"
export CXXFLAGS="$CFLAGS"
cm_common=(-G "Unix Makefiles" -DCMAKE_BUILD_TYPE=Release "-DCMAKE_C_FLAGS_RELEASE=-O2 -DNDEBUG"
           "-DCMAKE_CXX_FLAGS_RELEASE=-O2 -DNDEBUG" -DCMAKE_POSITION_INDEPENDENT_CODE=ON
           -DBUILD_SHARED_LIBS=OFF -DCMAKE_INSTALL_PREFIX="$prefix" -DCMAKE_INSTALL_LIBDIR=lib
           -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_PACKAGE_PREFER_CONFIG=OFF -DBUILD_TESTING=OFF)

# step NAME FUNCTION: runs FUNCTION once (a stamp marks it done), timing it.
step() {
  local name=$1 fn=$2
  if [ -f "$stamps/$name" ]; then say "$name: done earlier"; return 0; fi
  local t0; t0=$(date +%s)
  say "$name: building"
  rm -rf "${build:?}/$name"; mkdir -p "$build/$name"
  # set -e holds inside the function only where the subshell is not itself tested (no || here).
  set +e
  ( set -e; cd "$build/$name"; "$fn" ) > "$build/$name.log" 2>&1
  local rc=$?
  set -e
  if [ $rc -ne 0 ]; then tail -n 40 "$build/$name.log" >&2; die "$name failed (full log: $build/$name.log)"; fi
  local dt=$(( $(date +%s) - t0 ))
  say "$name: $dt s"
  echo "$name $dt s" >> "$cache/timings.txt.done"
  touch "$stamps/$name"
}

cmake_build() {   # cmake_build SOURCE-DIR [cmake options...]: configure, build, install here
  local s=$1; shift
  cmake -S "$s" -B . "${cm_common[@]}" "$@"
  nice cmake --build . -j "$jobs"
  cmake --install .
}

b_zlib() {
  cp -a "$(unpacked zlib)/." .
  CFLAGS="$CFLAGS" ./configure --static --prefix="$prefix" --libdir="$prefix/lib"
  nice make -j "$jobs" libz.a
  install -m 0644 libz.a "$prefix/lib/"
  install -m 0644 zlib.h zconf.h "$prefix/include/"
  mkdir -p "$prefix/lib/pkgconfig"
  install -m 0644 zlib.pc "$prefix/lib/pkgconfig/"
  # minizip (zlib's contrib/minizip, as Debian's libminizip-dev): Assimp's zip reader needs unzip.
  local m=contrib/minizip
  for f in ioapi unzip zip; do nice gcc $CFLAGS -I. -c "$m/$f.c" -o "minizip_$f.o"; done
  ar rcs libminizip.a minizip_ioapi.o minizip_unzip.o minizip_zip.o
  install -m 0644 libminizip.a "$prefix/lib/"
  mkdir -p "$prefix/include/minizip"
  install -m 0644 "$m/ioapi.h" "$m/unzip.h" "$m/zip.h" "$prefix/include/minizip/"
  printf '%s\n' "prefix=$prefix" 'libdir=${prefix}/lib' 'includedir=${prefix}/include/minizip' '' \
    'Name: minizip' 'Description: zip and unzip (zlib contrib/minizip)' 'Version: 1.2.13' \
    'Requires.private: zlib' 'Libs: -L${libdir} -lminizip' 'Cflags: -I${includedir}' \
    > "$prefix/lib/pkgconfig/minizip.pc"
}
b_libpng() {
  cmake_build "$(unpacked libpng)" -DPNG_SHARED=OFF -DPNG_STATIC=ON -DPNG_TESTS=OFF -DPNG_EXECUTABLES=OFF \
    -DZLIB_INCLUDE_DIR="$prefix/include" -DZLIB_LIBRARY="$prefix/lib/libz.a"
}
b_expat() {
  # Debian's patches test `#if XML_DTD == 1` (its autotools build defines XML_DTD to 1); expat's
  # CMake defines it empty, so the generated expat_config.h is given the value 1.
  cmake -S "$(unpacked expat)/expat" -B . "${cm_common[@]}" -DEXPAT_SHARED_LIBS=OFF -DEXPAT_BUILD_TOOLS=OFF \
    -DEXPAT_BUILD_EXAMPLES=OFF -DEXPAT_BUILD_TESTS=OFF -DEXPAT_BUILD_DOCS=OFF -DEXPAT_BUILD_FUZZERS=OFF \
    -DEXPAT_DTD=ON -DEXPAT_NS=ON
  sed -i 's/^#define XML_DTD$/#define XML_DTD 1/; s/^#define XML_NS$/#define XML_NS 1/' expat_config.h
  grep -q '^#define XML_DTD 1$' expat_config.h
  nice cmake --build . -j "$jobs"
  cmake --install .
}
b_yaml_cpp() {
  cmake_build "$(unpacked yaml-cpp)" -DYAML_CPP_BUILD_TESTS=OFF -DYAML_CPP_BUILD_TOOLS=OFF \
    -DYAML_CPP_BUILD_CONTRIB=OFF -DYAML_BUILD_SHARED_LIBS=OFF
}
b_pystring() {   # two files; upstream's CMakeLists builds a shared library only
  nice g++ $CXXFLAGS -c "$(unpacked pystring)/pystring.cpp" -o pystring.o
  ar rcs libpystring.a pystring.o
  install -m 0644 libpystring.a "$prefix/lib/"
  mkdir -p "$prefix/include/pystring"
  install -m 0644 "$(unpacked pystring)/pystring.h" "$prefix/include/pystring/"
}
b_imath() {
  cmake_build "$(unpacked imath)" -DPYTHON=OFF -DIMATH_INSTALL_PKG_CONFIG=ON
}
b_openexr() {    # OpenEXRCore only: the C library that src/output/exr.c calls
  local s; s=$(unpacked openexr)
  cmake -S "$s" -B . "${cm_common[@]}" -DOPENEXR_BUILD_TOOLS=OFF -DOPENEXR_INSTALL_EXAMPLES=OFF \
    -DOPENEXR_INSTALL_TOOLS=OFF -DOPENEXR_INSTALL_DOCS=OFF -DZLIB_ROOT="$prefix" \
    -DZLIB_INCLUDE_DIR="$prefix/include" -DZLIB_LIBRARY="$prefix/lib/libz.a"
  nice cmake --build . -j "$jobs" --target OpenEXRCore
  local lib; lib=$(find . -name 'libOpenEXRCore*.a' | head -n 1)
  [ -n "$lib" ] || { echo "no libOpenEXRCore*.a was built"; return 1; }
  install -m 0644 "$lib" "$prefix/lib/"
  mkdir -p "$prefix/include/OpenEXR"
  install -m 0644 "$s"/src/lib/OpenEXRCore/openexr*.h "$prefix/include/OpenEXR/"
  install -m 0644 cmake/OpenEXRConfig.h "$prefix/include/OpenEXR/"
}
b_ocio() {
  # The orig tarball of 2.1.3 misses includes that GCC 12 no longer brings in (Debian's patches,
  # not in the archive here, add them): force the standard headers it needs.
  CXXFLAGS="$CXXFLAGS -include cstring -include cstdint -include limits" \
  cmake_build "$(unpacked ocio)" -DOCIO_BUILD_APPS=OFF -DOCIO_BUILD_TESTS=OFF -DOCIO_BUILD_GPU_TESTS=OFF \
    -DOCIO_BUILD_PYTHON=OFF -DOCIO_BUILD_DOCS=OFF -DOCIO_BUILD_OPENFX=OFF -DOCIO_BUILD_NUKE=OFF \
    -DOCIO_BUILD_JAVA=OFF -DOCIO_INSTALL_EXT_PACKAGES=NONE -DOCIO_USE_SSE=ON \
    -Dexpat_ROOT="$prefix" -Dexpat_STATIC_LIBRARY=ON -Dyaml-cpp_ROOT="$prefix" -Dyaml-cpp_STATIC_LIBRARY=ON \
    -Dpystring_ROOT="$prefix" -DImath_ROOT="$prefix" -DImath_STATIC_LIBRARY=ON
}
b_cjson() {
  cmake_build "$(unpacked cjson)" -DBUILD_SHARED_AND_STATIC_LIBS=OFF -DENABLE_CJSON_TEST=OFF \
    -DENABLE_CJSON_UTILS=OFF -DENABLE_CUSTOM_COMPILER_FLAGS=OFF -DENABLE_TARGET_EXPORT=ON
}
b_assimp() {
  PKG_CONFIG_PATH="$prefix/lib/pkgconfig" \
  cmake_build "$(unpacked assimp)" -DASSIMP_BUILD_TESTS=OFF -DASSIMP_BUILD_ASSIMP_TOOLS=OFF \
    -DASSIMP_BUILD_SAMPLES=OFF -DASSIMP_BUILD_DOCS=OFF -DASSIMP_BUILD_ALL_IMPORTERS_BY_DEFAULT=OFF \
    -DASSIMP_BUILD_ALL_EXPORTERS_BY_DEFAULT=OFF -DASSIMP_BUILD_OBJ_IMPORTER=ON -DASSIMP_BUILD_PLY_IMPORTER=ON \
    -DASSIMP_NO_EXPORT=ON -DASSIMP_BUILD_ZLIB=OFF -DASSIMP_BUILD_DRACO=OFF -DASSIMP_INSTALL_PDB=OFF \
    -DASSIMP_WARNINGS_AS_ERRORS=OFF -DASSIMP_INJECT_DEBUG_POSTFIX=OFF -DASSIMP_BUILD_MINIZIP=OFF \
    -DZLIB_ROOT="$prefix" -DZLIB_INCLUDE_DIR="$prefix/include" -DZLIB_LIBRARY="$prefix/lib/libz.a" \
    "-DCMAKE_CXX_FLAGS=$CXXFLAGS -I/usr/include/utf8cpp -I$prefix/include/minizip"
}
b_embree() {
  # Embree 3's BVH8 code is compiled only for its AVX target, which AVX2 and AVX-512 need too:
  # SSE2 (the base), AVX, AVX2, AVX-512 (Debian's build also has SSE4.2). Results differ in the last
  # bits between Embree's ISAs, so the portable library matches the Debian build bit for bit where
  # both pick the same kernels: every CPU with AVX, AVX2 or AVX-512 (not SSE4.2-only ones).
  cmake -S "$(unpacked embree)" -B . "${cm_common[@]}" -DEMBREE_STATIC_LIB=ON -DEMBREE_TASKING_SYSTEM=INTERNAL \
    -DEMBREE_ISPC_SUPPORT=OFF -DEMBREE_TUTORIALS=OFF -DEMBREE_TUTORIALS_GLFW=OFF \
    -DEMBREE_MAX_ISA=NONE -DEMBREE_ISA_SSE2=ON -DEMBREE_ISA_SSE42=OFF -DEMBREE_ISA_AVX=ON \
    -DEMBREE_ISA_AVX2=ON -DEMBREE_ISA_AVX512=ON \
    -DEMBREE_GEOMETRY_TRIANGLE=ON -DEMBREE_GEOMETRY_INSTANCE=ON -DEMBREE_GEOMETRY_QUAD=OFF \
    -DEMBREE_GEOMETRY_CURVE=OFF -DEMBREE_GEOMETRY_SUBDIVISION=OFF -DEMBREE_GEOMETRY_USER=OFF \
    -DEMBREE_GEOMETRY_POINT=OFF -DEMBREE_GEOMETRY_GRID=OFF -DEMBREE_FILTER_FUNCTION=ON -DEMBREE_RAY_MASK=ON \
    -DEMBREE_RAY_PACKETS=OFF -DEMBREE_BACKFACE_CULLING=OFF -DEMBREE_IGNORE_INVALID_RAYS=OFF \
    -DEMBREE_STAT_COUNTERS=OFF -DEMBREE_ZIP_MODE=OFF "-DCMAKE_C_FLAGS_RELEASE=" "-DCMAKE_CXX_FLAGS_RELEASE="
  nice cmake --build . -j "$jobs"
  # Not `cmake --install`: it also installs readme.pdf, which the +dfsg tarball does not have.
  install -m 0644 ./*.a "$prefix/lib/"
  mkdir -p "$prefix/include/embree3"
  install -m 0644 "$(unpacked embree)"/include/embree3/*.h "$prefix/include/embree3/"
  ls "$prefix/lib/libembree_avx.a" "$prefix/lib/libembree_avx2.a" "$prefix/lib/libembree_avx512.a" >/dev/null
}

fetch_sources
step zlib b_zlib
step libpng b_libpng
step expat b_expat
step yaml-cpp b_yaml_cpp
step pystring b_pystring
step imath b_imath
step openexr b_openexr
step ocio b_ocio
step cjson b_cjson
step assimp b_assimp
step embree b_embree

# A record of what the prefix holds, for the handoff and for cmake/portable.cmake's messages.
{
  for line in "${sources[@]}"; do read -r name pkg ver orig mode <<<"$line"; echo "$name $pkg $ver ($mode)"; done
  echo "ocio opencolorio 2.1.3+dfsg orig ($ocio_url, sha256 $ocio_sha256)"
  echo "compiler $(gcc --version | head -n 1)"
} > "$prefix/VERSIONS"
total=$(( $(date +%s) - total_start ))
echo "total $total s (this run)" >> "$cache/timings.txt.done"
mv "$cache/timings.txt.done" "$cache/timings.txt"
rm -f "$cache/timings.txt.partial"
touch "$prefix/.complete"
say "done in $total s:"
sed 's/^/  /' "$cache/timings.txt" >&2
echo "$prefix"
