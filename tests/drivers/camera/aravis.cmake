# Aravis GigE Vision camera driver and its device-clock fit.

# Pure arithmetic: runs under the sanitizers.
rover_add_test(NAME drivers_camera_clock_fit_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/device_clock_fit_test.cc
  LIBS rover_drivers rover_test_support
  LABELS asan)

# Against a real GigE Vision device: arv-fake-gv-camera-0.8 on loopback,
# started per test. Its GVCP port (3956 on 127.0.0.1) takes one simulator at
# a time, hence the lock. Not asan: links the malloc counter.
rover_add_test(NAME hil_aravis_fake_gv_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/aravis_fake_gv_test.cc
  LIBS rover_drivers rover_sim rover_test_malloc_counter
  LABELS hil
  RESOURCE_LOCK gige)
