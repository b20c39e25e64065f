# Aravis camera figures against arv-fake-gv-camera-0.8 on loopback: frames/s,
# CPU per frame, hand-over and delivery latency, clock-fit cost. See the file
# comment of aravis_stream_bench.cc.
add_executable(bench_aravis_stream ${CMAKE_CURRENT_LIST_DIR}/aravis_stream_bench.cc)
rover_target_defaults(bench_aravis_stream)
target_link_libraries(bench_aravis_stream PRIVATE rover_drivers rover_sim CLI11::CLI11)
