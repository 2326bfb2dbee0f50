#!/usr/bin/env bash
# Installs the Debian 12 packages that algray's build, tests and benchmarks need; skips those already present.
set -euo pipefail

packages=(
  build-essential cmake pkg-config git
  ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers pocl-opencl-icd clinfo
  libglm-dev libopenexr-dev libpng-dev
  catch2 libtomlplusplus-dev nlohmann-json3-dev libcli11-dev
  libgmp-dev
  libcpp-httplib-dev  # `algray view`'s local web server
  chromium chromium-driver python3-selenium  # test_view_browser drives the page in headless Chromium
  python3
  python3-dev pybind11-dev  # the Python package (python/)
  python3-numpy python3-pytest python3-ipywidgets  # its arrays, its tests, and algray.explore's sliders
  jupyter-nbconvert python3-ipykernel python3-matplotlib  # the notebook of docs/, run headless by the tests
  munge slurmctld slurmd slurm-client  # test_slurm_array: a single-node Slurm started by the test itself
  libopenmpi-dev openmpi-bin  # `mpirun -n N algray batch` (the cluster layer) and test_mpi_batch
  clang-15                  # the sanitizer tree and libFuzzer targets of scripts/test.sh: the clang PoCL already
                            # depends on, with ASan, UBSan and libFuzzer in its libclang-common-15-dev; and
                            # test_kernel_portability's strict OpenCL C 1.2 front end
  ninja-build               # scripts/test.sh builds with Ninja
  help2man                  # the man page
)

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed'; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages already installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
