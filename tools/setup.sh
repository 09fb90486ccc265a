#!/usr/bin/env bash
# Installs what isph needs beyond the Rust toolchain, only if it is missing:
#   - HDF5 1.10 development files (Debian's libhdf5-dev) and pkg-config, for hdf5-metno;
#   - Python's pyvista (VTK's XDMF reader) and h5py, for tools/inspect_run.py and its test.
# Idempotent: a second run installs nothing.
set -euo pipefail
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"

apt_install() {
  if [ -z "${APT_UPDATED:-}" ]; then
    $SUDO apt-get update -qq
    APT_UPDATED=1
  fi
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "$@" >/dev/null
}

if ! command -v pkg-config >/dev/null 2>&1 || ! pkg-config --exists hdf5; then
  echo "setup: installing HDF5 (libhdf5-dev) and pkg-config"
  apt_install libhdf5-dev pkg-config
fi

if ! python3 -c "import pyvista, h5py" >/dev/null 2>&1; then
  echo "setup: installing pyvista and h5py"
  python3 -m pip install -q pyvista h5py
fi
if ! python3 -c "import pyvista" >/dev/null 2>&1; then
  # VTK's wheels load the system's libGL/libX11 even when nothing is rendered.
  echo "setup: installing the GL/X11 libraries VTK loads"
  apt_install libgl1 libxrender1 libxext6 libx11-6
fi
