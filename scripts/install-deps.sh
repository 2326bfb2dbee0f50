#!/usr/bin/env bash
# Installs the Debian 12 packages of one set, render (default) or test, skipping those already present.
#   scripts/install-deps.sh render   building `algray` and rendering: the first command of README.md
#   scripts/install-deps.sh test     render's set plus everything the whole test suite and the benchmarks need
# Each set is written once here; the render set stays small so that a fresh machine has its first picture in
# minutes (bench/RESULTS.md, "Set-up and test time").
set -euo pipefail

render_packages=(
  build-essential cmake ninja-build pkg-config git
  ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers pocl-opencl-icd
  libglm-dev libopenexr-dev libpng-dev
  libtomlplusplus-dev nlohmann-json3-dev libcli11-dev
  libgmp-dev
  libcpp-httplib-dev  # `algray view`'s local web server, in algray-full, which `algray` is built with
  libjpeg62-turbo-dev libwebp-dev  # `algray view`'s frames while the input moves: JPEG or WebP, in algray-full
)
test_packages=(
  clinfo catch2
  chromium chromium-driver python3-selenium  # test_view_browser drives the page in headless Chromium
  python3
  python3-dev pybind11-dev  # the Python package (python/)
  python3-numpy python3-pytest python3-ipywidgets  # its arrays, its tests, and algray.explore's sliders
  python3-sympy python3-pil  # Scene.from_equation of a sympy expression, and Image.to_pil(), in test_python
  jupyter-nbconvert python3-ipykernel python3-matplotlib  # the notebook of docs/, run headless by the tests
  munge slurmctld slurmd slurm-client  # test_slurm_array: a single-node Slurm started by the test itself
  libopenmpi-dev openmpi-bin  # `mpirun -n N algray batch` (the cluster layer) and test_mpi_batch
  clang-15                  # the sanitizer tree and libFuzzer targets of scripts/test.sh: the clang PoCL already
                            # depends on, with ASan, UBSan and libFuzzer in its libclang-common-15-dev; and
                            # test_kernel_portability's strict OpenCL C 1.2 front end
  help2man                  # the man page
  ffmpeg                    # `algray batch --video` runs the ffmpeg program; test_video writes and decodes videos
)

set_name=${1:-render}
case "$set_name" in
  render) packages=("${render_packages[@]}") ;;
  test) packages=("${render_packages[@]}" "${test_packages[@]}") ;;
  *) echo "install-deps: unknown set '$set_name' (render or test)" >&2; exit 2 ;;
esac

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages of the $set_name set already installed"
  exit 0
fi

echo "install-deps ($set_name): installing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
