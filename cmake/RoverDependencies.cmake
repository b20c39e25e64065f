# Every external dependency comes from a Debian 12 package installed by
# scripts/install_deps.sh; find them all in one place.
find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(PkgConfig REQUIRED)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
pkg_check_modules(LZ4 REQUIRED IMPORTED_TARGET liblz4)
find_package(ZLIB REQUIRED)

if(NOT ROVER_FUZZ)
  find_package(yaml-cpp REQUIRED)
  find_package(CLI11 REQUIRED)
  find_package(iceoryx_posh REQUIRED)
  find_package(iceoryx_hoofs REQUIRED)
  find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs calib3d video features2d)
  pkg_check_modules(APRILTAG REQUIRED IMPORTED_TARGET apriltag)
  find_package(OpenGL REQUIRED COMPONENTS OpenGL EGL)
  find_package(Ceres 2.1 REQUIRED)
  # Submap voxels and the composed global map (mapping/submap, mapping/compose).
  find_package(octomap 1.9 REQUIRED)
  # k-d trees of the submap matcher (mapping/loop), header only.
  find_package(nanoflann 1.4 REQUIRED)
  # Log service (firmware/runtime/log_service) and rover-log list/download:
  # cpp-httplib is a compiled library on Debian (its pkg-config flags select
  # the OpenSSL/zlib/brotli build it was compiled with); SHA-256 via libcrypto.
  pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
  find_package(OpenSSL REQUIRED COMPONENTS Crypto)
  # sd_notify (readiness, watchdog, status) of the firmware processes.
  pkg_check_modules(SYSTEMD REQUIRED IMPORTED_TARGET libsystemd)
  # Cameras on GigE Vision / USB3 Vision (drivers/camera, Aravis 0.8) and
  # GPIO lines through the character device (drivers/gpio, libgpiod v1).
  pkg_check_modules(ARAVIS REQUIRED IMPORTED_TARGET aravis-0.8)
  pkg_check_modules(GPIOD REQUIRED IMPORTED_TARGET libgpiod)
  # The team's radio link between rovers (core/link/dds): Cyclone DDS's C API,
  # idlc (cyclonedds-tools) for the datagram type.
  find_package(CycloneDDS 0.10 REQUIRED)
  if(ROVER_BUILD_TESTS)
    find_package(GTest REQUIRED)
    include(GoogleTest)
  endif()
  if(ROVER_BUILD_BENCHMARKS)
    find_package(benchmark REQUIRED)
  endif()
endif()
