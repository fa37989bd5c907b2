#!/usr/bin/env bash
# Installs what building, testing and running airseg needs on Debian 12, from Debian's packages only.
set -euo pipefail
packages=(
  cmake ninja-build g++ pkg-config ccache
  libboost-dev libboost-program-options-dev libyaml-cpp-dev libspdlog-dev libfmt-dev
  libgpiod-dev libsodium-dev nlohmann-json3-dev zlib1g-dev libmosquitto-dev libssl-dev
  libgtest-dev libgmock-dev libbenchmark-dev valgrind
  clang libclang-rt-14-dev clang-tidy
  # The ground map's page (Leaflet) and its browser test (headless chromium).
  libjs-leaflet chromium
  # The fleet test's MQTT broker and its clients (mosquitto_sub, _pub, _passwd); openssl makes the TLS test's
  # certificates.
  mosquitto mosquitto-clients openssl
)
sudo=""
if [ "$(id -u)" -ne 0 ]; then
  sudo="sudo"
fi
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# node and npm run the independent MAVLink implementation of the interoperability test. Some machines carry
# a Node.js build with its own npm; install Debian's only when there is none.
command -v node >/dev/null || missing+=(nodejs)
command -v npm >/dev/null || missing+=(npm)
if [ "${#missing[@]}" -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
