# What the shell tests (tests/mpi, tests/slurm) share: sourced after setting test_name.
#   fail MESSAGE           ends the test with "test_name: MESSAGE"
#   mpi_ready              fails unless mpirun is here, and sets mpirun_2: two local ranks, one PoCL thread each
#   growing_ball_scene     the scene the sweeps grow (parameter r), on standard output

fail() {
  echo "$test_name: $*" >&2
  exit 1
}

mpi_ready() {
  command -v mpirun >/dev/null ||
    fail "mpirun not found: install openmpi-bin and libopenmpi-dev (scripts/install-deps.sh does)"
  command -v python3 >/dev/null || fail "python3 not found (it reads the logs and stats)"
  # CI runs as root; the timeout turns a deadlock into a failure.
  mpirun_2=(timeout 120 mpirun --oversubscribe --allow-run-as-root -n 2 -x POCL_MAX_PTHREAD_COUNT=1)
}

growing_ball_scene() {
  cat <<'TOML'
[surface]
equation = "x^2+y^2+z^2-r^2"
[parameters]
r = 1
[extent]
radius = 2
[camera]
eye = [0, 0, 5]
look_at = [0, 0, 0]
up = [0, 1, 0]
fov_y = 45
[[light]]
position = [3, 4, 5]
TOML
}
