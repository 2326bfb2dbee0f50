#!/bin/bash
# What help2man reads as `algray --help` for the man page: the top-level help, then each subcommand's help
# under its own heading, because help2man only ever runs --help once.
#
# usage: man_help.sh ALGRAY_BINARY --help
set -euo pipefail
algray=$1
shift
[ "${1:-}" = "--help" ] || { echo "man_help.sh: only --help is supported" >&2; exit 2; }

# argv[0] is what CLI11 prints in "Usage:", so run it as plain "algray" rather than by its build path.
run() { (exec -a algray "$algray" "$@"); }

run --help
for sub in render probe batch devices; do
  printf '\nalgray %s:\n' "$sub"
  # The subcommand's own "Options:"/"Positionals:" headings would each open another OPTIONS section, and -h
  # is listed once already.
  # Description and usage indented, so help2man keeps them under this heading rather than starting a new one.
  run "$sub" --help | sed -e '/^Options:$/d' -e '/^Positionals:$/d' -e '/^  -h,--help /d' -e '/^$/d' \
    -e '1s/^/  /' -e '2s/^/\n  /' -e '2s/$/\n/'
done
