#!/usr/bin/env bash
# Builds the libFuzzer targets with the `fuzz` preset (clang), writes the seed
# corpus into build/fuzz/corpus and fuzzes the MCAP reader.
#
#   FUZZ_SECONDS  total fuzzing time (default 60)
#
# Exits nonzero if the build fails or the fuzzer finds a crash, sanitizer
# report, leak, timeout or out-of-memory; the reproducer is written to
# build/fuzz/artifacts/.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cd "$root"

cmake --preset fuzz
cmake --build --preset fuzz

build="$root/build/fuzz"
corpus="$build/corpus"
artifacts="$build/artifacts"
mkdir -p "$corpus" "$artifacts"
"$build/tests/fuzz/make_mcap_seed_corpus" "$corpus"

"$build/tests/fuzz/fuzz_mcap_reader" \
  -max_total_time="${FUZZ_SECONDS:-60}" \
  -rss_limit_mb=2048 \
  -timeout=30 \
  -print_final_stats=1 \
  -artifact_prefix="$artifacts/" \
  "$corpus"
