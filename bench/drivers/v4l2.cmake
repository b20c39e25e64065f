# V4L2 camera figures against vivid: frames/s, CPU per frame, hand-over
# latency. Runs inside the HIL bench VM (hil/bench/run_in_vm.sh), where
# /dev/video0 is vivid; see the file comment of v4l2_vivid_bench.cc.
add_executable(bench_v4l2_vivid ${CMAKE_CURRENT_LIST_DIR}/v4l2_vivid_bench.cc)
rover_target_defaults(bench_v4l2_vivid)
target_link_libraries(bench_v4l2_vivid PRIVATE rover_drivers CLI11::CLI11)
