#!/usr/bin/env bash
# Installs Mesa's software Vulkan driver (lavapipe) where no Vulkan driver is installed, so wgpu
# finds an adapter on machines without a GPU. Skips what is already there.
set -euo pipefail
have_driver() {
  dpkg -s mesa-vulkan-drivers >/dev/null 2>&1 && dpkg -s libvulkan1 >/dev/null 2>&1 && return 0
  # Another vendor's driver (a real GPU) with the loader.
  ls /usr/share/vulkan/icd.d/*.json /etc/vulkan/icd.d/*.json >/dev/null 2>&1 &&
    ldconfig -p 2>/dev/null | grep -q libvulkan.so.1
}
if have_driver; then
  exit 0
fi
sudo=""
if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
echo "lineao: installing the software Vulkan driver (mesa-vulkan-drivers)" >&2
$sudo apt-get update -qq
$sudo env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq mesa-vulkan-drivers libvulkan1 >/dev/null
