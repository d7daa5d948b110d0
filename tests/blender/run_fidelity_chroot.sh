#!/bin/bash
# Runs tests/blender/test_fidelity.py in the Blender of a chroot made by scripts/blender-chroots.sh
# on branch `addon` (/var/cache/dwivedi/chroots/trixie: Blender 4.3, sid: Blender 5.2), against
# that Blender's own Cycles. Usage (root: chroot and a private mount namespace):
#   bash tests/blender/run_fidelity_chroot.sh trixie|sid BUILD_DIR [RESULTS_DIR]
# The add-on is installed from BUILD_DIR/dwivedi_bake.zip. Where BUILD_DIR/libdwivedi.so.1 needs
# libraries beyond glibc / libstdc++ / libgcc (today's Debian 12 build), the host's copies go in
# the stage's deps/ and the test preloads them and the library (DWIVEDI_PRELOAD_DIR,
# DWIVEDI_LIBRARY) with RTLD_DEEPBIND before the add-on loads it, so that it binds to its own
# Embree 3 / OpenEXR and not to the ones Blender has loaded: a test set-up only, never part of a
# package (as branch addon's run_package_tests.py).
# DWIVEDI_CHROOT_TEST=test_textures.py runs that test instead (its figures: texture_figures.json).
set -euo pipefail
suite=${1:?trixie or sid}
test=${DWIVEDI_CHROOT_TEST:-test_fidelity.py}
figures=$([[ "$test" == test_textures* ]] && echo texture_figures.json || echo fidelity_figures.json)
build=$(cd "${2:?build dir}" && pwd)
results=${3:-$build/tests/fidelity-$suite}
root=/var/cache/dwivedi/chroots/$suite
here=$(cd "$(dirname "$0")" && pwd)
[ -x "$root/usr/bin/blender" ] || { echo "run_fidelity_chroot: no Blender in $root (make it with branch addon's scripts/blender-chroots.sh): skipped" >&2; exit 77; }
[ "$(id -u)" = 0 ] || { echo "run_fidelity_chroot: needs root (chroot, a private mount namespace): skipped" >&2; exit 77; }
stage_rel=/tmp/dwivedi-fidelity-$$
stage=$root$stage_rel
mkdir -p "$stage/deps" "$stage/home" "$results"
trap 'rm -rf "$stage"' EXIT
cp "$build/dwivedi_bake.zip" "$stage/"
mkdir -p "$stage/lib" && cp -L "$build/libdwivedi.so.1" "$stage/lib/"
cp "$here"/harness.py "$here"/scenes.py "$here/$test" "$stage/"
base='^(linux-vdso|libc\.so|libm\.so|libstdc\+\+|libgcc_s|ld-linux|libpthread|libdl\.so|librt\.so)'
ldd "$build/libdwivedi.so.1" | awk '/=> \//{print $1, $3}' | while read -r name path; do
    if ! [[ $name =~ $base ]]; then cp -L "$path" "$stage/deps/$name"; fi
done
n=$(ls "$stage/deps" | wc -l)
if [ "$n" -gt 0 ]; then
    # One dlopen with RTLD_DEEPBIND of a wrapper that needs Blender's own malloc (jemalloc, where this
    # Blender links it) before the library: the library then binds to its own Embree 3 / OpenEXR but
    # to the process's malloc (a separate glibc malloc aborts: free(): invalid pointer).
    malloc_lib=$(chroot "$root" sh -c "ldd /usr/bin/blender" | awk '/jemalloc|tbbmalloc_proxy/{print $3; exit}')
    mkdir -p "$stage/wrap"
    echo 'int dwv_fidelity_wrapper(void) { return 1; }' > "$stage/wrap/wrap.c"
    cc -shared -fPIC -o "$stage/wrap/libdwvwrap.so" "$stage/wrap/wrap.c" -Wl,--no-as-needed \
        ${malloc_lib:+"$root$malloc_lib"} "$stage/lib/libdwivedi.so.1" -Wl,--disable-new-dtags \
        -Wl,-rpath,'$ORIGIN/../lib:$ORIGIN/../deps'
    echo "run_fidelity_chroot: scratch set-up: $n host libraries beside the library (not self-contained), loaded" \
         "by a RTLD_DEEPBIND wrapper${malloc_lib:+ with $malloc_lib first}"
fi
env_vars=(BLENDER_USER_SCRIPTS=$stage_rel/home/scripts BLENDER_USER_CONFIG=$stage_rel/home/config
          BLENDER_USER_DATAFILES=$stage_rel/home/datafiles DWIVEDI_TEST_HOME=$stage_rel/home
          DWIVEDI_ADDON_ZIP=$stage_rel/dwivedi_bake.zip DWIVEDI_PRELOAD=$stage_rel/wrap/libdwvwrap.so DWIVEDI_LIBRARY=$stage_rel/lib/libdwivedi.so.1
          PYTHONDONTWRITEBYTECODE=1 HOME=$stage_rel/home TMPDIR=$stage_rel/home)
if [ "$n" -gt 0 ] && [ -n "${DWIVEDI_FIDELITY_OCIO_FROM:-}" ]; then
    # The host library's OpenColorIO (2.1) cannot read a newer Blender's config (5.2: version 2.5):
    # the display PNG (not compared here) then fails the bake. Scratch: Blender and the bake both use
    # the config of another chroot's Blender (DWIVEDI_FIDELITY_OCIO_FROM=trixie: Blender 4.3's).
    cp -r "/var/cache/dwivedi/chroots/$DWIVEDI_FIDELITY_OCIO_FROM/usr/share/blender/datafiles/colormanagement" "$stage/ocio"
    env_vars+=(OCIO=$stage_rel/ocio/config.ocio)
    echo "run_fidelity_chroot: scratch set-up: OCIO=$DWIVEDI_FIDELITY_OCIO_FROM's Blender config (the host OpenColorIO is older)"
fi
for v in DWIVEDI_FIDELITY_EVENT_CAP DWIVEDI_FIDELITY_ONLY DWIVEDI_FIDELITY_RESOLUTION DWIVEDI_FIDELITY_CYCLES_SPP DWIVEDI_FIDELITY_DWIVEDI_SPP; do
    [ -n "${!v:-}" ] && env_vars+=("$v=${!v}")
done
set +e
unshare --mount --propagation private sh -c 'mount -t proc proc "$1/proc" && shift && exec chroot "$@"' sh "$root" \
    "$root" env "${env_vars[@]}" nice blender -b --factory-startup --python-exit-code 1 --python "$stage_rel/$test"
status=$?
set -e
cp "$stage/home/$figures" "$results/" 2>/dev/null || true
rm -rf "$results/work" && cp -r "$stage/home/work" "$results/work" 2>/dev/null || true
echo "run_fidelity_chroot: $suite: exit $status; figures in $results/$figures"
exit $status
