# StereoPairer over scripted MonoCameras. The same source builds twice: the
# behaviour tests under asan, and (ROVER_TEST_MALLOC_COUNTER) the
# no-allocation check with the malloc counter, which asan must not link.
rover_add_test(NAME drivers_stereo_pairer_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/stereo_pairer_test.cc
  LIBS rover_drivers LABELS asan)
rover_add_test(NAME drivers_stereo_pairer_alloc_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/stereo_pairer_test.cc
  LIBS rover_drivers rover_test_malloc_counter)
target_compile_definitions(drivers_stereo_pairer_alloc_test PRIVATE ROVER_TEST_MALLOC_COUNTER=1)
