#!/usr/bin/env bash
# Packs the built algray, its OpenCL tests and the libraries they load into .gpu/bundle.tar.xz, for a lent GPU
# machine (another distribution, nothing of ours installed) where bench/gpu/check.sh unpacks and runs them.
set -euo pipefail
cd "$(dirname "$0")/../.."

# Tests that need no MPI, Slurm, Python or browser, and no second device (test_multi_device).
tests=(test_batch test_cli test_config test_diagnostic_images test_expression test_fp64 test_hard_rays test_image_io
       test_jsurf test_kernels test_lanes test_probe test_public_api test_reference_agree test_reliability
       test_render_plan test_scene test_scenes_agree test_secondary_rays test_shading test_shadows
       test_shadows_batched test_solver_ref test_surfaces test_univariate)

stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/build/apps/algray" "$stage/build/tests" "$stage/build/bench" "$stage/lib"
# algray-full: test_cli checks that `algray view` reaches it.
install -s build/apps/algray/algray build/apps/algray/algray-full "$stage/build/apps/algray/"
install -s build/bench/exr_compare "$stage/build/bench/"
for t in "${tests[@]}" image_writer_tool; do install -s "build/tests/$t" "$stage/build/tests/"; done
printf '%s\n' "${tests[@]}" > "$stage/tests.txt"
# The tests find scenes and the CLI through this path, compiled in.
pwd > "$stage/source_dir"

# Every library the binaries load except the C and C++ runtimes, which the target has in a newer version.
for f in "$stage"/build/*/*/algray* "$stage"/build/tests/* "$stage"/build/bench/*; do ldd "$f"; done |
  awk '$3 ~ /^\// {print $3}' | sort -u |
  grep -Ev '/(libc|libm|libstdc\+\+|libgcc_s|libpthread|libdl|librt)\.so' |
  while read -r lib; do cp -L "$lib" "$stage/lib/"; done

mkdir -p .gpu
tar -C "$stage" -cJf .gpu/bundle.tar.xz .
grep -qx '/.gpu/' .git/info/exclude 2>/dev/null || { mkdir -p .git/info; echo '/.gpu/' >> .git/info/exclude; }
ls -l .gpu/bundle.tar.xz
