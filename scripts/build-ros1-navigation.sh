#!/usr/bin/env bash
# Builds the real ROS 1 navigation stack's move_base (ros-planning/navigation, noetic-devel)
# from source against Debian bookworm's ROS 1 packages, for benchmarks/barn_ros1_baseline.py
# (BARN's published baseline: move_base + navfn + TrajectoryPlannerROS, run against
# roverlab's simulator over ROS 1). Debian packages ROS 1's core (ros_comm 1.15, tf2,
# actionlib, pluginlib, dynamic_reconfigure, laser_geometry, the message packages) but
# not the navigation stack.
#
#   scripts/build-ros1-navigation.sh WORKSPACE [NAVIGATION_SOURCE]
#
# WORKSPACE: a catkin workspace to build in (created; keep it outside the repository),
#   e.g. /work/rosnav_ws. The result is WORKSPACE/devel (source WORKSPACE/devel/setup.bash).
# NAVIGATION_SOURCE: a checkout of ros-planning/navigation at noetic-devel; without it the
#   script clones https://github.com/ros-planning/navigation (branch noetic-devel).
#
# Only the packages move_base needs for BARN are built: nav_core, costmap_2d, voxel_grid,
# navfn, base_local_planner, clear_costmap_recovery, rotate_recovery, move_base (no amcl,
# map_server, dwa_local_planner, global_planner). Tests are off. Idempotent; needs root
# (or sudo) only to install missing Debian packages. About 10 minutes on 2 cores.
# Needs no source patch: Debian's pluginlib 5.2 keeps ROS 1's API (createInstance
# returning boost::shared_ptr, plugin discovery through rospack exports).
set -euo pipefail
if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  echo "usage: $0 WORKSPACE [NAVIGATION_SOURCE]" >&2
  exit 2
fi
ws=$(realpath -m "$1")
src=${2:-}
if [ -n "$src" ] && [ ! -f "$src/move_base/package.xml" ]; then
  echo "$src: not a ros-planning/navigation checkout (no move_base/package.xml)" >&2
  exit 2
fi

# Debian's build dependencies of the eight packages. The ros-*-msgs packages hold the
# .msg definitions message generation reads (the lib*-msgs-dev ones only the headers).
packages=(
  catkin python3-catkin-pkg cmake g++ make ros-cmake-modules
  ros-message-generation ros-message-runtime python3-genmsg python3-gencpp python3-genpy
  libroscpp-dev libroslib-dev librostest-dev libmessage-filters-dev libactionlib-dev
  libtf2-dev libtf2-ros-dev libtf2-geometry-msgs-dev libtf2-sensor-msgs-dev
  liblaser-geometry-dev libangles-dev pluginlib-dev
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libstd-msgs-dev libstd-srvs-dev libnav-msgs-dev libmap-msgs-dev libmove-base-msgs-dev
  libvisualization-msgs-dev libeigen3-dev libboost-dev libboost-thread-dev
  ros-std-msgs ros-geometry-msgs ros-nav-msgs ros-sensor-msgs ros-actionlib-msgs
  ros-move-base-msgs ros-map-msgs
  ros-core python3-actionlib python3-move-base-msgs
)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends \
    -o DPkg::Lock::Timeout=300 "${missing[@]}"
fi

mkdir -p "$ws/src"
if [ -z "$src" ]; then
  if [ ! -d "$ws/src/navigation" ]; then
    git clone --depth 1 -b noetic-devel https://github.com/ros-planning/navigation \
      "$ws/src/navigation"
  fi
else
  rm -rf "$ws/src/navigation"
  ln -s "$(realpath "$src")" "$ws/src/navigation"
fi

# Debian's own Python (catkin_pkg, empy, genmsg live there), never a venv's or pyenv's.
cd "$ws"
env -i HOME="$HOME" PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  nice -n 5 /usr/bin/python3 /usr/bin/catkin_make \
  -DPYTHON_EXECUTABLE=/usr/bin/python3 \
  -DCATKIN_WHITELIST_PACKAGES="nav_core;costmap_2d;voxel_grid;navfn;base_local_planner;clear_costmap_recovery;rotate_recovery;move_base" \
  -DCATKIN_ENABLE_TESTING=OFF -DCMAKE_BUILD_TYPE=Release -j2
test -x "$ws/devel/lib/move_base/move_base"
echo "built: $ws/devel/lib/move_base/move_base (source $ws/devel/setup.bash)"
