# Xbus decoding: MTData2 packets parsed (framing, checksum) and decoded per
# second and ns per packet, clean and with corrupted bytes.
add_executable(bench_xbus_decode ${CMAKE_CURRENT_LIST_DIR}/xbus_decode_bench.cc)
rover_target_defaults(bench_xbus_decode)
target_link_libraries(bench_xbus_decode PRIVATE rover_drivers)
