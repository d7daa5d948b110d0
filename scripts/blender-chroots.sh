#!/bin/bash
# Clean Debian chroots holding only Blender, Python and an X server for Blender's UI (xvfb, xauth:
# tests/blender/test_ui.py), for testing the add-on's packages in other Blenders: trixie (Blender
# 4.3) and sid (Blender 5.2).
#
#   sudo bash scripts/blender-chroots.sh [SUITE...]      (default: trixie sid)
#
# Each is made once with mmdebstrap (a Debian 12 package) from the Debian archive apt uses on this
# machine, into ${DWV_CHROOT_DIR:-/var/cache/dwivedi/chroots}/SUITE, outside the clone, and reused
# while it is complete: the marker file SUITE/.dwivedi-chroot-complete is written last, so an
# interrupted build (no marker) is removed and made again. The marker lists the packages: a chroot
# made with an older list gets the missing ones installed in place (apt-get in the chroot; made
# again only if that fails), so a running test in it is not pulled from under it. Concurrent callers
# wait for each other
# (flock). Prints "SUITE DIR seconds" per chroot on stdout; exit status 1 with a message when one
# cannot be made (not root, no mmdebstrap, no network). About 1.5-2.5 minutes and 0.9-1.3 GB each.
set -euo pipefail

root_dir=${DWV_CHROOT_DIR:-/var/cache/dwivedi/chroots}
packages=(blender python3 xvfb xauth)
package_list=$(IFS=,; echo "${packages[*]}")
suites=("$@")
[ ${#suites[@]} -gt 0 ] || suites=(trixie sid)

die() { echo "blender-chroots: $*" >&2; exit 1; }

mirror() {
  # The first Debian archive URI apt uses here (deb822 sources, else sources.list).
  local uri=""
  if [ -n "${DWV_CHROOT_MIRROR:-}" ]; then echo "$DWV_CHROOT_MIRROR"; return; fi
  for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    uri=$(awk '/^URIs:/ { for (i = 2; i <= NF; i++) if ($i !~ /security/) { print $i; exit } }' "$f")
    [ -n "$uri" ] && break
  done
  if [ -z "$uri" ] && [ -f /etc/apt/sources.list ]; then
    uri=$(awk '$1 == "deb" && $0 !~ /security/ { for (i = 2; i <= NF; i++) if ($i ~ /^[a-z]+:\/\//) { print $i; exit } }' \
          /etc/apt/sources.list)
  fi
  echo "${uri:-http://deb.debian.org/debian}"
}

[ "$(id -u)" = 0 ] || die "making chroots needs root (mmdebstrap, chroot); run it with sudo, or run the tests with DWV_TEST_QUICK=1, which leaves the other Blenders out"
command -v mmdebstrap >/dev/null || die "mmdebstrap is not installed: apt-get install mmdebstrap (a Debian 12 package)"
mkdir -p "$root_dir"
url=$(mirror)

for suite in "${suites[@]}"; do
  case "$suite" in
    trixie|sid|bookworm|forky) ;;
    *) die "unknown suite '$suite' (trixie, sid)" ;;
  esac
  dir="$root_dir/$suite"
  marker="$dir/.dwivedi-chroot-complete"
  exec 9>"$root_dir/.$suite.lock"
  flock 9
  start=$(date +%s.%N)
  if [ -f "$marker" ] && ! grep -qx "packages=$package_list" "$marker"; then
    # Only the packages it lacks (apt-get install of an installed one would upgrade it: Blender).
    missing=()
    for p in "${packages[@]}"; do
      chroot "$dir" dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    echo "blender-chroots: $dir was made with another package list: installing ${missing[*]:-nothing} in it" >&2
    if [ ${#missing[@]} -eq 0 ] || {
         chroot "$dir" env DEBIAN_FRONTEND=noninteractive apt-get update -q >>"$root_dir/$suite.log" 2>&1 &&
         chroot "$dir" env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
           "${missing[@]}" >>"$root_dir/$suite.log" 2>&1; }; then
      grep -v '^packages=' "$marker" >"$marker.tmp"
      echo "packages=$package_list" >>"$marker.tmp"
      mv "$marker.tmp" "$marker"
    else
      tail -n 5 "$root_dir/$suite.log" >&2
      echo "blender-chroots: installing into $dir failed: making it again" >&2
      rm -f "$marker"
    fi
  fi
  if [ ! -f "$marker" ]; then
    if [ -e "$dir" ]; then
      echo "blender-chroots: $dir is incomplete (no marker): making it again" >&2
      rm -rf --one-file-system "$dir"
    fi
    partial="$dir.partial"
    rm -rf --one-file-system "$partial"
    extra=()
    # sid's Release file can be past its Valid-Until date on a snapshot mirror.
    [ "$suite" = sid ] && extra=(--aptopt='Acquire::Check-Valid-Until "false"')
    echo "blender-chroots: making $dir (mmdebstrap $suite from $url)" >&2
    if ! nice mmdebstrap --variant=apt --include="$package_list" "${extra[@]}" "$suite" "$partial" "$url" \
         >"$root_dir/$suite.log" 2>&1; then
      tail -n 20 "$root_dir/$suite.log" >&2
      rm -rf --one-file-system "$partial"
      die "mmdebstrap $suite failed (log: $root_dir/$suite.log)"
    fi
    [ -x "$partial/usr/bin/blender" ] || { rm -rf --one-file-system "$partial"; die "$suite: no /usr/bin/blender in the chroot"; }
    mv "$partial" "$dir"
    version=$(chroot "$dir" dpkg-query -W -f '${Version}' blender)
    printf 'suite=%s\nmirror=%s\nblender=%s\nmade=%s\npackages=%s\n' "$suite" "$url" "$version" "$(date -u +%FT%TZ)" \
      "$package_list" >"$marker.tmp"
    mv "$marker.tmp" "$marker"
  fi
  end=$(date +%s.%N)
  flock -u 9
  echo "$suite $dir $(awk -v a="$start" -v b="$end" 'BEGIN { printf "%.1f", b - a }')"
done
