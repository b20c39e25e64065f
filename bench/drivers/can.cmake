# CAN wheel-drive frames received and decoded per second through SocketCAN
# (run it where a CAN interface exists: inside the HIL bench VM on vcan0, or
# on a board), against the decoder alone in the same run.
add_executable(bench_can_decode ${CMAKE_CURRENT_LIST_DIR}/can_decode_bench.cc)
rover_target_defaults(bench_can_decode)
target_link_libraries(bench_can_decode PRIVATE rover_drivers CLI11::CLI11)
