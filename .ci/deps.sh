# shellcheck shell=bash
# Installs the Debian packages iclap needs, only those that are missing.
# Usage: source .ci/deps.sh; iclap_install_deps [extra-package...]
ICLAP_BASE_PACKAGES=(cmake make g++ pkg-config ccache libeigen3-dev libnanoflann-dev
                     doctest-dev libbenchmark-dev libhidapi-dev)

iclap_install_deps() {
  local missing=() pkg
  for pkg in "${ICLAP_BASE_PACKAGES[@]}" "$@"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed"; then
      missing+=("$pkg")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  local sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  echo "Installing missing Debian packages: ${missing[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
}

# ccache hashes the paths under the checkout relative to it, so a clone in
# another directory reuses what an earlier clone compiled (the scripts source
# this file from the checkout's root). Builds with debug information (the
# sanitizer half) still hash their build directory, which their line tables
# name, and -D values with absolute paths (test fixtures) hash as they are.
if [ -z "${CCACHE_BASEDIR:-}" ]; then export CCACHE_BASEDIR="$PWD"; fi

# CMake arguments shared by the scripts: ccache when present.
iclap_cmake_launcher_args() {
  if command -v ccache >/dev/null 2>&1; then echo "-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"; fi
}
