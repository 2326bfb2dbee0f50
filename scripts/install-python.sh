#!/usr/bin/env bash
# Installs the built Python package (build/python/algray) where `python3 -c "import algray"` finds it: into
# Debian's python3 (cmake --install, component python), and, when the python3 first on PATH is another
# interpreter of the same version (pyenv, say), into that one's site-packages too: the module's ABI is the version's.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi
$SUDO cmake --install build --component python
built_for=$(/usr/bin/python3 -c 'import sys; print("%d.%d" % sys.version_info[:2])')
if command -v python3 >/dev/null; then
  read -r path_exe path_version path_site < <(python3 -c \
    'import sys, sysconfig; print(sys.executable, "%d.%d" % sys.version_info[:2], sysconfig.get_paths()["platlib"])')
  if [ "$path_exe" != "$(/usr/bin/python3 -c 'import sys; print(sys.executable)')" ] &&
     [ "$path_version" = "$built_for" ]; then
    $SUDO rm -rf "$path_site/algray"
    $SUDO cp -r build/python/algray "$path_site/algray"
  fi
fi
python3 -c 'import algray, sys; print("install-python:", algray.__version__, "for", sys.executable)'
/usr/bin/python3 -c 'import algray, sys; print("install-python:", algray.__version__, "for", sys.executable)'
