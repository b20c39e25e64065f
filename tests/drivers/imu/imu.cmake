# IMU drivers: Xbus codec and parser, MTData2, device clock mapping, ADIS16448
# burst format, raw serial port and spidev. The drivers against simulated
# devices are tested in tests/hil/sim/devices.
rover_add_test(NAME drivers_imu_test
  SOURCES
    ${CMAKE_CURRENT_LIST_DIR}/xbus_protocol_test.cc
    ${CMAKE_CURRENT_LIST_DIR}/xbus_parser_test.cc
    ${CMAKE_CURRENT_LIST_DIR}/mt_data2_packet_test.cc
    ${CMAKE_CURRENT_LIST_DIR}/clock_offset_tracker_test.cc
    ${CMAKE_CURRENT_LIST_DIR}/adis16448_burst_test.cc
    ${CMAKE_CURRENT_LIST_DIR}/serial_port_test.cc
    ${CMAKE_CURRENT_LIST_DIR}/spidev_device_test.cc
  LIBS rover_drivers
  LABELS asan)
