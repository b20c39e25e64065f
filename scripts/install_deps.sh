#!/usr/bin/env bash
# Installs everything the project needs, from Debian 12 packages and pinned npm
# packages. Idempotent: packages already present are skipped, so a second run
# is quick and never prompts. Later work appends to the lists below, one
# package per line with the reason it is here.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"

# package                      reason
DEBIAN_PACKAGES=(
  build-essential            # GCC 12 toolchain (C++20)
  cmake                      # build system, >= 3.25 on Debian 12
  ninja-build                # generator used by every preset
  ccache                     # compiler cache shared by every preset and every clone (cmake/RoverCcache.cmake)
  pkg-config                 # locates zstd / lz4 / yaml-cpp
  git                        # version stamp in logs, fresh-clone checks
  clang                      # libFuzzer targets (tests/fuzz)
  libclang-rt-14-dev         # libFuzzer + sanitizer runtimes for clang
  clang-format               # style check of the sources in CI
  libeigen3-dev              # geometry, estimator linear algebra
  libyaml-cpp-dev            # board configuration files (core/config)
  libgtest-dev               # unit tests
  libgmock-dev               # unit tests (matchers, mocks of interfaces)
  libbenchmark-dev           # printed benchmark figures (bench/)
  libzstd-dev                # MCAP chunk compression (default)
  zstd                       # command-line zstd, for inspecting logs
  liblz4-dev                 # MCAP chunk compression (option)
  zlib1g-dev                 # CRC-32 of MCAP records (zlib crc32)
  libcli11-dev               # command-line parsing of host tools
  iceoryx                    # iox-roudi, the shared-memory broker
  libiceoryx-posh-dev        # iceoryx publish/subscribe API (core/ipc)
  nodejs                     # independent MCAP reader for conformance tests
  libopencv-dev              # simulator image effects/distortion, SGBM check; later VO and depth
  libapriltag-dev            # AprilTag 36h11 family: rendered tags, detection checks
  libegl-dev                 # headless OpenGL context for the stereo renderer (EGL)
  libgl-dev                  # OpenGL API used by the renderer
  libegl-mesa0               # Mesa's EGL driver (surfaceless platform, no display needed)
  libgl1-mesa-dri            # Mesa's llvmpipe software rasteriser: renders without a GPU
  liboctomap-dev             # submap voxels and the global map (mapping/submap, mapping/compose): .bt/.ot
  libnanoflann-dev           # k-d trees of the submap matcher (mapping/loop): keypoints, descriptors, ICP
  libceres-dev               # pose-graph back end (mapping/graph, rover-graph): Manifold API, sparse Cholesky
  libsuitesparse-dev         # CHOLMOD (mapping/graph): sparse LL^T of the SE-Sync Newton solver and the certificate's definiteness test
  rt-tests                   # cyclictest: reference wake-up latency for scripts/rt_latency.sh
  libsystemd-dev             # sd_notify: roverd's systemd watchdog and readiness notification
  libcpp-httplib-dev         # HTTP log service on the board and `rover-log list/download` (cpp-httplib 0.11)
  qemu-system-x86            # HIL bench (hil/bench): boots Debian's kernel under TCG with real vcan/vivid
  linux-image-amd64          # HIL bench: the guest kernel and its vcan, can-raw, can-isotp, vivid, 9p modules
  busybox-static             # HIL bench: the guest's initramfs userland (/init, insmod, mount)
  iproute2                   # HIL bench: `ip link add vcan0 type vcan` inside the guest (run from the host fs)
  can-utils                  # candump/cansend for poking the bench's vcan0 by hand
  aravis-tools               # arv-fake-gv-camera-0.8: a real GigE Vision device on loopback for the Aravis tests
  libaravis-dev              # Aravis 0.8: GigE Vision / USB3 Vision cameras (drivers/camera)
  libgpiod-dev               # libgpiod v1: GPIO trigger output and edge events (drivers/gpio)
  libusb-1.0-0-dev           # required by aravis-0.8.pc (pkg-config fails without it)
  libssl-dev                 # SHA-256 of served logs (OpenSSL libcrypto EVP), also needed by cpp-httplib
  python3                    # scripts/check_link_graph.py: the library layering test (tests/architecture)
  cyclonedds-dev             # Cyclone DDS C API: the team's radio link between rovers (core/link/dds)
  cyclonedds-tools           # idlc (generates the link's DDS type at build time) and ddsperf
)

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null; then SUDO="sudo"; else
    echo "install_deps: need root or sudo to install Debian packages" >&2; exit 1
  fi
fi

missing=()
for pkg in "${DEBIAN_PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q "install ok installed" || missing+=("$pkg")
done
# npm ships inside some Node.js builds (NodeSource) and separately in Debian's;
# installing Debian's npm next to a NodeSource node would conflict.
command -v npm >/dev/null || missing+=(npm)

if ((${#missing[@]})); then
  echo "install_deps: installing ${missing[*]}"
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
else
  echo "install_deps: all Debian packages present"
fi

# npm packages, pinned by tests/conformance/package-lock.json.
if [[ -f "$root/tests/conformance/package-lock.json" ]]; then
  lock_hash=$(sha256sum "$root/tests/conformance/package-lock.json" | cut -d' ' -f1)
  stamp="$root/tests/conformance/node_modules/.lock-hash"
  if [[ ! -f "$stamp" || "$(cat "$stamp")" != "$lock_hash" ]]; then
    echo "install_deps: npm ci in tests/conformance"
    (cd "$root/tests/conformance" && npm ci --no-audit --no-fund --loglevel=error)
    echo "$lock_hash" >"$stamp"
  fi
fi
