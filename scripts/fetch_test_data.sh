#!/usr/bin/env bash
# Fetch the real photos some tests use, from Debian's darknet package, into build/test-data/.
# Only the package file is downloaded and unpacked: nothing is installed on the system and none
# of the package's dependencies (OpenCV with GUI libraries) come along. Idempotent; when the
# system already has the package installed, its files are used instead.
# Prints the folder holding the photos; tests read it from SAILOR_DARKNET_DATA.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
target="$root/build/test-data"
photos_relative="usr/share/darknet/data"

if [ -f "/$photos_relative/dog.jpg" ]; then echo "/$photos_relative"; exit 0; fi
if [ -f "$target/$photos_relative/dog.jpg" ]; then echo "$target/$photos_relative"; exit 0; fi

mkdir -p "$target/packages"
cd "$target/packages"
if ! apt-get download darknet >/dev/null 2>&1; then
  # The package lists may be missing or stale on a new machine.
  if [ "$(id -u)" = 0 ]; then apt-get update -qq >/dev/null 2>&1 || true; fi
  apt-get download darknet >/dev/null 2>&1 || {
    echo "[test-data] could not download Debian's darknet package; tests that need its photos" \
         "will be skipped (on Debian/Ubuntu run 'sudo apt-get update' and try again)" >&2
    exit 0
  }
fi
dpkg-deb -x darknet_*.deb "$target"
echo "$target/$photos_relative"
