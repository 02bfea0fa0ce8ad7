# Shared by scripts/demo, scripts/test and scripts/bench: install Debian packages (once),
# build the catkin workspace under .build/ (incremental), source it.
# Sourced, not executed.
set -eo pipefail

PP_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PP_WS="${PP_ROOT}/.build/ws"
# Debian's Python must win over any pyenv Python on PATH (../shared/ENVIRONMENT.md, gotcha 1).
export PATH="/usr/bin:/bin:/usr/local/cuda/bin:${PATH}"

PP_PACKAGES=(
  build-essential cmake pkg-config python3
  catkin ros-core ros-core-dev rosbash rospack-tools ros-environment ros-message-generation
  ros-message-runtime libroscpp-dev python3-rospy libactionlib-dev python3-actionlib
  libactionlib-msgs-dev python3-actionlib-msgs libtf2-ros-dev libtf2-eigen-dev
  libtf2-geometry-msgs-dev python3-tf2-ros libpcl-conversions-dev libpcl-msgs-dev ros-pcl-msgs
  python3-pcl-msgs libpcl-dev python3-rostest librostest-dev python3-roslaunch python3-rosunit
  librosbag-dev python3-rosbag rosout python3-rostopic python3-rosnode python3-rosmsg
  liburdfdom-dev liburdf-dev libopencv-dev libeigen3-dev libvisualization-msgs-dev
  python3-visualization-msgs libgeometry-msgs-dev python3-geometry-msgs libshape-msgs-dev
  python3-shape-msgs python3-yaml
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libgtest-dev googletest rviz librviz-dev xvfb xauth imagemagick
  libbullet-dev libbullet-extras-dev libmujoco-dev libtbb-dev libbenchmark-dev
  libcli11-dev nlohmann-json3-dev
  clang libclang-rt-dev llvm
)

pp_install_deps() {
  local missing=()
  for p in "${PP_PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ ${#missing[@]} -eq 0 ]; then
    return 0
  fi
  echo "[place_planner] installing ${#missing[@]} Debian packages: ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
}

pp_build() {
  mkdir -p "${PP_WS}/src"
  # The package is linked into the workspace, so edits need no copy.
  [ -L "${PP_WS}/src/place_planner" ] || ln -sfn "${PP_ROOT}" "${PP_WS}/src/place_planner"
  local cuda_flag=()
  [ -n "${PLACE_PLANNER_WITH_CUDA:-}" ] && cuda_flag=("-DPLACE_PLANNER_WITH_CUDA=${PLACE_PLANNER_WITH_CUDA}")
  (cd "${PP_WS}" && catkin_make -j2 -DCMAKE_BUILD_TYPE=Release \
      -DPYTHON_EXECUTABLE=/usr/bin/python3 -DPython3_EXECUTABLE=/usr/bin/python3 \
      "${cuda_flag[@]}" "$@")
}

pp_source() {
  set +u
  # shellcheck disable=SC1091
  source "${PP_WS}/devel/setup.bash"
}

# Runs ../shared/tools/scansim (simulated depth-camera scans) with the given arguments, after
# installing the Debian packages it needs (once).
pp_scansim() {
  local saved=("${PP_PACKAGES[@]}")
  PP_PACKAGES=(python3-open3d python3-numpy python3-scipy)
  pp_install_deps
  PP_PACKAGES=("${saved[@]}")
  /usr/bin/python3 "${PP_ROOT}/../shared/tools/scansim/scansim.py" "$@"
}
