# V4L2 camera driver on the host (no capture device here): pixel format
# conversions against hand-made buffers, options validation and the start-up
# errors for a missing or non-video device. Streaming is proven against vivid
# on the HIL bench (tests/hil/bench, hil_bench_v4l2_test).
rover_add_test(NAME drivers_camera_v4l2_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/v4l2_pixel_format_test.cc
          ${CMAKE_CURRENT_LIST_DIR}/v4l2_camera_test.cc
  LIBS rover_drivers rover_test_support
  LABELS asan)
# The same conversion source with the malloc counter (never under asan):
# converting the uncompressed formats does not allocate.
rover_add_test(NAME drivers_camera_v4l2_alloc_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/v4l2_pixel_format_test.cc
  LIBS rover_drivers rover_test_malloc_counter)
target_compile_definitions(drivers_camera_v4l2_alloc_test PRIVATE ROVER_TEST_MALLOC_COUNTER=1)
