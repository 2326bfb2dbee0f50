#!/usr/bin/env bash
# Times README's two commands in a chroot of a bare Debian 12 (debootstrap minbase), as on a fresh machine.
#
#   bash bench/bare_debian.sh DIR render   # `bash scripts/render-default.sh` from nothing installed
#   bash bench/bare_debian.sh DIR test     # the same, then the test set's packages (`install-deps.sh test`)
#
# The test suite itself is timed by bench/setup_time.py on the machine: in a chroot, Slurm's daemons do not start
# (munged refuses slurmd's credential), so test_slurm_array fails there and nowhere else.
# Run as root. DIR keeps the bare system's tarball (made on first use by debootstrap from this machine's Debian
# mirror, apt's lists and package cache emptied) and the chroot, which each run unpacks again from the tarball.
# HEAD of this repository is copied in with `git archive` (the chroot has no git yet). The times are printed and
# the commands' output is in DIR/render.log and DIR/test-deps.log; bench/RESULTS.md ("Set-up and test time") records
# them by hand beside bench/setup_time.py's table.
set -euo pipefail
[ "$(id -u)" -eq 0 ] || { echo "bare_debian: run as root" >&2; exit 1; }
[ $# -eq 2 ] && { [ "$2" = render ] || [ "$2" = test ]; } || { sed -n 4,5p "$0" >&2; exit 2; }
repo=$(cd "$(dirname "$0")/.." && pwd)
dir=$(mkdir -p "$1" && cd "$1" && pwd)
root=$dir/root
tarball=$dir/bare-bookworm.tar

mounted() { awk -v r="$root" '$2 == r || index($2, r "/") == 1 { print $2 }' /proc/self/mounts | sort -r; }
unmount_all() { for m in $(mounted); do umount "$m" 2>/dev/null || umount -l "$m"; done; }
trap unmount_all EXIT

if [ ! -f "$tarball" ]; then
  command -v debootstrap >/dev/null || { apt-get update -qq && apt-get install -y -qq debootstrap; }
  # This machine's Debian mirror (a deb822 .sources file or sources.list, whichever it has).
  mirror=$(cat /etc/apt/sources.list.d/*.sources /etc/apt/sources.list 2>/dev/null |
             grep -oE '^(URIs:|deb) +https?://[^ ]+' | head -1 | awk '{print $2}' || true)
  rm -rf --one-file-system "$root"
  debootstrap --variant=minbase bookworm "$root" "${mirror:-http://deb.debian.org/debian}" > "$dir/debootstrap.log"
  # Apt as on this machine (its mirror), name resolution, and nothing cached: a fresh machine downloads it all.
  rm -f "$root/etc/apt/sources.list"
  cp /etc/apt/sources.list.d/* "$root/etc/apt/sources.list.d/" 2>/dev/null || true
  [ -f /etc/apt/sources.list ] && cp /etc/apt/sources.list "$root/etc/apt/"
  cp /etc/resolv.conf /etc/hosts "$root/etc/"
  rm -rf "$root"/var/lib/apt/lists/* "$root"/var/cache/apt/archives/*.deb
  tar --numeric-owner -cf "$tarball" -C "$root" .
fi

unmount_all
[ -z "$(mounted)" ] || { echo "bare_debian: still mounted under $root" >&2; exit 1; }
rm -rf --one-file-system "$root"
mkdir -p "$root"
tar --numeric-owner -xpf "$tarball" -C "$root"
mount -t proc proc "$root/proc"
mount -t sysfs sysfs "$root/sys"
mount --rbind /dev "$root/dev"
mount --make-rslave "$root/dev"
mkdir -p "$root/root/algray"
git -C "$repo" archive --format=tar HEAD | tar -xf - --no-same-owner -C "$root/root/algray"

in_chroot() {  # in_chroot LOG COMMAND: runs it in the copy with a clean environment, prints its wall time
  local start=$SECONDS
  chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
    bash -c "cd /root/algray && $2" > "$1" 2>&1 || { echo "bare_debian: '$2' failed; see $1" >&2; exit 1; }
  echo "bare_debian: '$2' took $((SECONDS - start)) s"
}
in_chroot "$dir/render.log" "bash scripts/render-default.sh"
if [ "$2" = test ]; then in_chroot "$dir/test-deps.log" "scripts/install-deps.sh test"; fi
