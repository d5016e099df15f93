#!/usr/bin/env bash
# The real MERLIN2 stack for compatibility tests: builds what a MERLIN2 workspace would hold, from
# the source checkouts in $SAILOR_UPSTREAM (the layout of ../shared/upstream: kant/, yasmin/,
# merlin2/, simple_node/, waypoint_navigation/, ...), and prints the path of a shell file that puts
# it on the paths. Usage:
#   . "$(scripts/upstream_env.sh)"        # then python / pytest see kant_dao, yasmin, merlin2_* ...
# With SAILOR_UPSTREAM unset it builds nothing and prints the path of an empty file, so the same
# line works everywhere and the upstream tests skip with their reason.
#
# What it does, nothing of it copied into the project (several of these projects are GPL-3):
#   1. builds their interface packages (kant_msgs, yasmin_msgs, merlin2_msgs, ...) with the venv's
#      cmake and rosidl into build/upstream/install, as setup.sh builds merlin2_sailor_interfaces;
#   2. names their pure-Python packages (kant_dto, kant_dao, yasmin, simple_node, merlin2_*, ...) in
#      PYTHONPATH straight from the checkout.
# A hash of the sources and of this script is kept beside the build: a second run builds nothing.
# Needs the project's .venv (make setup).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="$root/.venv"
out="$root/build/upstream"
prefix="$out/install"
env_file="$out/env.sh"

say() { printf '[upstream] %s\n' "$*" >&2; }
die() { printf '[upstream] error: %s\n' "$*" >&2; exit 1; }

mkdir -p "$out"
if [ -z "${SAILOR_UPSTREAM:-}" ]; then
  : > "$out/none.sh"
  echo "$out/none.sh"
  exit 0
fi
upstream="$(cd "$SAILOR_UPSTREAM" 2>/dev/null && pwd)" \
  || die "SAILOR_UPSTREAM=$SAILOR_UPSTREAM is not a folder"
[ -x "$venv/bin/python" ] || die "no .venv here; run 'make setup' first"

# Interface packages, in build order (a package after those it depends on).
interfaces=(
  kant/kant_msgs
  yasmin/yasmin_msgs
  merlin2/merlin2_arch/merlin2_msgs
  waypoint_navigation/waypoint_navigation_msgs
  text_to_speech/text_to_speech_msgs
  speech_to_text/speech_to_text_msgs
  vision_msgs/vision_msgs
  yolo_ros/yolo_msgs
  geometry2/tf2_msgs
  geometry2/tf2
  geometry2/tf2_py
)
# Interface packages of which only part builds here: name, then the interface files generated
# (Nav2's nav2_msgs also needs geographic_msgs, which the ROS 2 wheels lack; NavigateToPose does not).
subset_name=nav2_msgs
subset_source=navigation2/nav2_msgs
subset_files=(action/NavigateToPose.action)
subset_depends=(std_msgs builtin_interfaces geometry_msgs action_msgs)
# Projects whose Python packages go on the path as they are in the checkout.
python_projects=(kant yasmin simple_node merlin2 waypoint_navigation)
# Python packages whose folder is not named after them (tf2_ros_py holds tf2_ros).
python_roots=(geometry2/tf2_ros_py)

for package in "${interfaces[@]}" "$subset_source"; do
  [ -f "$upstream/$package/package.xml" ] || die "$upstream/$package is missing; SAILOR_UPSTREAM must \
hold the layout of ../shared/upstream (see its README)"
done

# A package of our own that generates only subset_files, read in place from the upstream package
# (rosidl's "base:relative" form), so nothing of it is copied.
write_subset_package() {
  local folder="$1" file interfaces_list="" depends_xml="" depends_list=""
  rm -rf "$folder" && mkdir -p "$folder"
  for file in "${subset_files[@]}"; do interfaces_list+=" \"$upstream/$subset_source:$file\""; done
  for file in "${subset_depends[@]}"; do
    depends_xml+="  <depend>$file</depend>"$'\n'
    depends_list+=" $file"
  done
  cat > "$folder/package.xml" <<XML
<?xml version="1.0"?>
<package format="3">
  <name>$subset_name</name>
  <version>0.0.0</version>
  <description>Part of $subset_source (${subset_files[*]}), built for SAILOR's compatibility tests.</description>
  <maintainer email="none@example.com">merlin2_sailor tests</maintainer>
  <license>Apache-2.0</license>
  <buildtool_depend>ament_cmake</buildtool_depend>
  <buildtool_depend>rosidl_default_generators</buildtool_depend>
$depends_xml  <member_of_group>rosidl_interface_packages</member_of_group>
  <export><build_type>ament_cmake</build_type></export>
</package>
XML
  cat > "$folder/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.8)
project($subset_name)
find_package(ament_cmake REQUIRED)
find_package(rosidl_default_generators REQUIRED)
foreach(dependency$depends_list)
  find_package(\${dependency} REQUIRED)
endforeach()
rosidl_generate_interfaces(\${PROJECT_NAME}$interfaces_list DEPENDENCIES$depends_list)
ament_export_dependencies(rosidl_default_runtime)
ament_package()
CMAKE
}

sources_hash="$(
  { sha256sum "${BASH_SOURCE[0]}" "$venv/.sailor-deps.sha" 2>/dev/null || true
    for package in "${interfaces[@]}"; do
      find "$upstream/$package" -type f -print0 | sort -z | xargs -0 sha256sum
    done
    for file in "${subset_files[@]}"; do sha256sum "$upstream/$subset_source/$file"; done; } | sha256sum | cut -d' ' -f1
)"

if [ ! -f "$out/.built.sha" ] || [ "$(cat "$out/.built.sha")" != "$sources_hash" ]; then
  say "building the upstream interfaces into $prefix (first run: about 2 minutes)"
  rm -rf "$prefix" "$out/packages"
  "$venv/bin/python" "$root/scripts/fix_ros_cmake_paths.py" "$venv" >&2
  # rosidl finds its type supports through the ament index: the venv's, then what is built here.
  export AMENT_PREFIX_PATH="$prefix:$venv"
  write_subset_package "$out/subsets/$subset_name"
  for package in "${interfaces[@]}" "subset:$subset_name"; do
    name="$(basename "${package#subset:}")"
    source_folder="$upstream/$package"
    [ "${package#subset:}" != "$package" ] && source_folder="$out/subsets/$name"
    log="$out/$name.log"
    say "  $name"
    if ! { "$venv/bin/cmake" -S "$source_folder" -B "$out/packages/$name" \
             -DCMAKE_PREFIX_PATH="$prefix;$venv" -DCMAKE_INSTALL_PREFIX="$prefix" \
             -DPython3_EXECUTABLE="$venv/bin/python" -DBUILD_TESTING=OFF \
           && "$venv/bin/cmake" --build "$out/packages/$name" -j "$(nproc 2>/dev/null || echo 2)" \
           && "$venv/bin/cmake" --install "$out/packages/$name"; } > "$log" 2>&1; then
      tail -n 20 "$log" >&2
      die "building $name failed; the whole log is in $log"
    fi
  done
  printf '%s\n' "$sources_hash" > "$out/.built.sha"
fi

# The Python roots: each package folder (one with a package.xml) that holds a Python package of its
# own name, as colcon would install it.
python_paths=("$prefix/lib/python3.11/site-packages")
for project in "${python_projects[@]}"; do
  [ -d "$upstream/$project" ] || die "$upstream/$project is missing"
  while IFS= read -r manifest; do
    folder="$(dirname "$manifest")"
    [ -f "$folder/$(basename "$folder")/__init__.py" ] && python_paths+=("$folder")
  done < <(find "$upstream/$project" -name package.xml | sort)
done

for root in "${python_roots[@]}"; do
  [ -d "$upstream/$root" ] || die "$upstream/$root is missing"
  python_paths+=("$upstream/$root")
done
joined_paths="$(IFS=:; echo "${python_paths[*]}")"
cat > "$env_file" <<EOF
# Written by scripts/upstream_env.sh from SAILOR_UPSTREAM=$upstream; source it.
export SAILOR_UPSTREAM="$upstream"
export PYTHONPATH="$joined_paths\${PYTHONPATH:+:\$PYTHONPATH}"
export LD_LIBRARY_PATH="$prefix/lib\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}"
export AMENT_PREFIX_PATH="$prefix:$venv\${AMENT_PREFIX_PATH:+:\$AMENT_PREFIX_PATH}"
EOF
echo "$env_file"
