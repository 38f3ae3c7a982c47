#!/usr/bin/env bash
# Makes sure a Vulkan loader, a driver (ICD) and, with --validation, the Khronos validation layer
# are installed (with --python, also Python 3 with venv and pip, for the Python package). Installs
# them with apt when root or with passwordless sudo; otherwise prints exactly what to install and
# exits 1.
# Usage: scripts/ensure-vulkan.sh [--validation] [--xvfb] [--python]
set -euo pipefail

need_validation=0
need_xvfb=0
need_python=0
for a in "$@"; do
  case "$a" in
    --validation) need_validation=1 ;;
    --xvfb) need_xvfb=1 ;;
    --python) need_python=1 ;;
  esac
done

# True when any of the glob patterns matches a file.
have_any() {
  local pattern f
  for pattern in "$@"; do
    for f in $pattern; do
      [ -e "$f" ] && return 0
    done
  done
  return 1
}

missing=()
# meshoptimizer (the `meshopt` crate) is C++, compiled by cargo's build.
if ! command -v c++ >/dev/null 2>&1; then
  missing+=(g++)
fi
if ! ldconfig -p 2>/dev/null | grep 'libvulkan\.so\.1' >/dev/null; then
  missing+=(libvulkan1)
fi
if ! have_any '/usr/share/vulkan/icd.d/*.json' '/etc/vulkan/icd.d/*.json' && [ -z "${VK_ICD_FILENAMES:-}${VK_DRIVER_FILES:-}" ]; then
  missing+=(mesa-vulkan-drivers)
fi
if [ "$need_validation" = 1 ] && ! have_any '/usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json' '/etc/vulkan/explicit_layer.d/VkLayer_khronos_validation.json'; then
  missing+=(vulkan-validationlayers)
fi
if [ "$need_xvfb" = 1 ] && ! command -v Xvfb >/dev/null 2>&1; then
  missing+=(xvfb)
fi
# Libraries the viewer's X11 backend (winit) loads at run time.
if [ "$need_xvfb" = 1 ] && ! ldconfig -p 2>/dev/null | grep 'libxkbcommon-x11\.so\.0' >/dev/null; then
  missing+=(libx11-xcb1 libxkbcommon-x11-0 libxcursor1 libxrandr2 libxi6)
fi

# The Python package's tests: an interpreter that can make a virtual environment with pip.
if [ "$need_python" = 1 ] && ! python3 -c 'import venv, ensurepip' >/dev/null 2>&1; then
  missing+=(python3 python3-venv python3-pip)
fi

if [ "${#missing[@]}" -eq 0 ]; then
  exit 0
fi

bash "$(dirname "$0")/apt-install.sh" "${missing[@]}"
