#!/usr/bin/env bash
# Install the Debian packages tensor-servo needs, only those that are missing.
# Idempotent: a second run installs nothing. Needs root (or sudo) only when something is missing.
set -euo pipefail

need=()
have_pkg() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
for p in verilator iverilog libeigen3-dev cmake yosys g++ make; do
  have_pkg "$p" || need+=("$p")
done
# The Python venv and extension build need ensurepip and Python.h; a pyenv/conda Python brings its
# own, Debian's python3 needs python3-venv and python3-dev.
python3 -c "import ensurepip" 2>/dev/null || need+=(python3-venv)
inc=$(python3 -c "import sysconfig; print(sysconfig.get_paths()['include'])")
[ -f "$inc/Python.h" ] || need+=(python3-dev)

if [ ${#need[@]} -eq 0 ]; then
  echo "setup: Debian packages present"
  exit 0
fi
echo "setup: installing Debian packages: ${need[*]}"
if [ "$(id -u)" -eq 0 ]; then SUDO=""; elif command -v sudo >/dev/null; then SUDO="sudo"; else
  echo "setup: error: need root to install ${need[*]} (run 'make setup' as root)" >&2; exit 1
fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${need[@]}"
