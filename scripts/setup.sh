#!/usr/bin/env bash
# Idempotent set-up of merlin2_sailor in ./.venv, with nothing installed by hand:
#   1. a Python 3.11 virtual environment (the ROS 2 Jazzy wheels are built for CPython 3.11 only);
#   2. the pinned dependencies of requirements.txt and requirements-build.txt, and those of
#      requirements-nodeps.txt without their declared dependencies;
#   3. merlin2_sailor_interfaces built with cmake + rosidl and installed into the venv;
#   4. merlin2_sailor itself, in editable mode.
# Each step records a hash of its inputs in .venv/.sailor-*.sha and is skipped when they have not
# changed, so a second run with nothing to do takes about a second.
# Environment: SAILOR_PYTHON=/path/to/python3.11 picks the interpreter; SAILOR_QUIET=1 hides pip's
# progress.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$root/.venv"
build_dir="$root/build/merlin2_sailor_interfaces"
cd "$root"

say() { printf '[setup] %s\n' "$*"; }
die() { printf '[setup] error: %s\n' "$*" >&2; exit 1; }

inputs_hash() {  # hash of the named files and of every file under the named folders
  local path existing=()
  for path in "$@"; do [ -e "$path" ] && existing+=("$path"); done
  find "${existing[@]}" -type f -print0 | sort -z | xargs -0 sha256sum | sha256sum | cut -d' ' -f1
}
up_to_date() { [ -f "$venv/.sailor-$1.sha" ] && [ "$(cat "$venv/.sailor-$1.sha")" = "$2" ]; }
mark_done() { printf '%s\n' "$2" > "$venv/.sailor-$1.sha"; }

is_python311() { "$1" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))' 2>/dev/null; }

find_python311() {
  local candidate
  for candidate in "${SAILOR_PYTHON:-}" python3.11 python3 /usr/bin/python3.11 \
                   "$HOME"/.pyenv/versions/3.11*/bin/python3.11; do
    [ -n "$candidate" ] || continue
    if command -v "$candidate" >/dev/null 2>&1 && is_python311 "$candidate"; then
      command -v "$candidate"; return 0
    fi
  done
  return 1
}

# 1. The virtual environment.
if [ ! -x "$venv/bin/python" ] || ! is_python311 "$venv/bin/python"; then
  python311="$(find_python311)" || die "Python 3.11 not found. The ROS 2 Jazzy wheels exist for \
CPython 3.11 only. Install it (Debian/Ubuntu: 'apt install python3.11 python3.11-venv'; or \
'pyenv install 3.11') or point SAILOR_PYTHON at a python3.11 executable, then run this again."
  say "creating .venv with $python311"
  rm -rf "$venv"
  "$python311" -m venv "$venv" || die "'$python311 -m venv' failed; on Debian/Ubuntu install python3.11-venv."
fi
python="$venv/bin/python"
pip_quiet=()
[ "${SAILOR_QUIET:-0}" = "1" ] && pip_quiet=(-q)
pip_install() { "$python" -m pip install --disable-pip-version-check "${pip_quiet[@]}" "$@"; }

# 2. Pinned dependencies.
deps_hash="$(inputs_hash requirements.txt requirements-build.txt requirements-nodeps.txt constraints.txt)"
if ! up_to_date deps "$deps_hash"; then
  say "installing pinned dependencies (first run: about a minute)"
  constraint_args=()
  [ -f constraints.txt ] && constraint_args=(-c constraints.txt)
  pip_install -r requirements.txt -r requirements-build.txt "${constraint_args[@]}" \
    || die "pip could not install the pinned dependencies (see above)."
  pip_install --no-deps -r requirements-nodeps.txt \
    || die "pip could not install requirements-nodeps.txt (see above)."
  mark_done deps "$deps_hash"
fi

# 3. The interfaces package, built by cmake into the venv.
interfaces_hash="$(inputs_hash merlin2_sailor_interfaces scripts/setup.sh "$venv/.sailor-deps.sha")"
if ! up_to_date interfaces "$interfaces_hash"; then
  command -v cc >/dev/null 2>&1 || command -v gcc >/dev/null 2>&1 \
    || die "no C compiler found; rosidl needs one to build merlin2_sailor_interfaces \
(Debian/Ubuntu: 'apt install build-essential')."
  say "building merlin2_sailor_interfaces (about 20 s)"
  # The ROS wheels' exported CMake files name the include folders of the machine that built them;
  # point them at this venv's Python and NumPy headers.
  "$python" "$root/scripts/fix_ros_cmake_paths.py" "$venv"
  rm -rf "$build_dir"
  cmake_log="$root/build/interfaces-build.log"
  mkdir -p "$root/build"
  if ! { "$venv/bin/cmake" -S merlin2_sailor_interfaces -B "$build_dir" \
           -DCMAKE_PREFIX_PATH="$venv" -DCMAKE_INSTALL_PREFIX="$venv" \
           -DPython3_EXECUTABLE="$python" -DBUILD_TESTING=OFF \
         && "$venv/bin/cmake" --build "$build_dir" -j "$(nproc 2>/dev/null || echo 2)" \
         && "$venv/bin/cmake" --install "$build_dir"; } > "$cmake_log" 2>&1; then
    tail -n 30 "$cmake_log" >&2
    die "building merlin2_sailor_interfaces failed; the whole log is in $cmake_log"
  fi
  "$python" -c 'import merlin2_sailor_interfaces.msg' \
    || die "merlin2_sailor_interfaces was built but does not import; see $cmake_log"
  mark_done interfaces "$interfaces_hash"
fi

# 4. merlin2_sailor itself, editable, so changes to the sources take effect without reinstalling.
package_hash="$(inputs_hash setup.py setup.cfg package.xml "$venv/.sailor-deps.sha")"
if ! up_to_date package "$package_hash"; then
  say "installing merlin2_sailor (editable)"
  pip_install --no-deps --no-build-isolation -e . || die "installing merlin2_sailor failed (see above)."
  mark_done package "$package_hash"
fi

# 5. The networks exported for the inference runtime (OpenVINO), so no node spends its first start
#    converting them. Each export is named by a hash of its source: a second run exports nothing.
say "exporting the networks for OpenVINO (first run: about a minute)"
"$venv/bin/sailor" export-models > "$root/build/export-models.log" 2>&1 \
  || { tail -n 20 "$root/build/export-models.log" >&2; die "exporting the models failed; the log is in build/export-models.log"; }

say "ready: $venv ($("$python" --version))"
