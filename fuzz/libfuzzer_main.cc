// libFuzzer entry point of one fuzz target, chosen at build time
// (MJSLAM_FUZZ_TARGET, e.g. "config"): see fuzz/README.md for the long run.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fuzz/fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const mjslam::fuzz::Target& target = mjslam::fuzz::FindTarget(MJSLAM_FUZZ_TARGET);
  static const std::string scratch =
      "/tmp/mjslam_fuzz_" + std::string(MJSLAM_FUZZ_TARGET) + "_" + std::to_string(::getpid());
  target.read(std::string_view(reinterpret_cast<const char*>(data), size), scratch);
  return 0;
}
