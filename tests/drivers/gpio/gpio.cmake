# GPIO drivers through the fake chip (Debian's kernel has no gpio-sim or
# gpio-mockup); the real chip's start-up errors through libgpiod. The
# allocation checks link the malloc counter and therefore stay out of asan.
rover_add_test(NAME drivers_gpio_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/fake_gpio_chip_test.cc
          ${CMAKE_CURRENT_LIST_DIR}/gpio_line_edge_source_test.cc
          ${CMAKE_CURRENT_LIST_DIR}/gpio_camera_trigger_test.cc
          ${CMAKE_CURRENT_LIST_DIR}/gpio_loopback_check_test.cc
          ${CMAKE_CURRENT_LIST_DIR}/libgpiod_chip_test.cc
  LIBS rover_drivers LABELS asan)
rover_add_test(NAME drivers_gpio_alloc_test
  SOURCES ${CMAKE_CURRENT_LIST_DIR}/gpio_alloc_test.cc
  LIBS rover_drivers rover_test_malloc_counter)
