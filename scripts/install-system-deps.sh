#!/usr/bin/env bash
# Debian packages roverlab's runs and tests need. Idempotent; needs root (or sudo) only
# when something is missing.
#   chromium: the dashboard's browser tests (Playwright drives /usr/bin/chromium).
#   ROS 1 (ros_comm 1.15, Debian bookworm): the reference the interop tests hold roverlab
#   against (a real roscore, rospy, rostopic, rosbag, actionlib, tf2_ros, ...). They are
#   run with /usr/bin/python3, never inside the project's venv.
#   rviz, xvfb, imagemagick: Debian's real rviz 1.14 run against roverlab's simulator under
#   a virtual X server (Xvfb; software Mesa is enough for its OpenGL), screenshots taken
#   with imagemagick's `import -window root` (docs/ros1.md, "Real rviz").
#   tmux: the newcomer check (tests/newcomer) runs the README's commands in terminals.
set -euo pipefail
packages=(
  chromium tmux
  ros-core python3-rospy python3-rostopic python3-rosservice python3-rosparam
  python3-rosnode python3-rosbag python3-actionlib python3-tf2-ros
  ros-robot-state-publisher liburdfdom-tools rviz xvfb imagemagick
  python3-std-msgs python3-std-srvs python3-geometry-msgs python3-sensor-msgs
  python3-nav-msgs python3-tf2-msgs python3-move-base-msgs python3-visualization-msgs
)
missing=()
for p in "${packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
SUDO=""
[ "$(id -u)" -ne 0 ] && SUDO="sudo"
$SUDO apt-get update -qq
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends \
  -o DPkg::Lock::Timeout=300 "${missing[@]}"
