// A bounded mutation run over the fuzz targets (fuzz/fuzz_targets.h): every
// seed input of fuzz/corpus/TARGET/ and a fixed number of mutants of each,
// made by a seeded generator (the same mutants on every run). Each must be
// read or refused with the reader's error, never crash, hang, throw anything
// else or be accepted while breaking a promise of the target. The libFuzzer
// programs (fuzz/README.md) search much further; this run keeps what they
// found fixed.

#include <unistd.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fuzz/fuzz_targets.h"

namespace mjslam::fuzz {
namespace {

namespace fs = std::filesystem;

// Mutants per seed input (the environment's MJSLAM_FUZZ_MUTANTS for a long
// run, fuzz/README.md), and the generator's seed (printed on failure).
int MutantsPerSeed() {
  const char* text = std::getenv("MJSLAM_FUZZ_MUTANTS");
  return text != nullptr && std::atoi(text) > 0 ? std::atoi(text) : 500;
}
constexpr std::uint64_t kSeed = 20261201;

// Pieces a mutation inserts: separators, signs, the spellings of special
// numbers, YAML indicators, a tab.
const std::vector<std::string> kPieces = {
    ",", "\n", "\r\n", "-", ".", "e", "9", "0", "nan", "inf", "-inf", ".inf", ".nan", "1e308",
    "1e999", "-1", "0x1p3", "\t", ": ", "[", "]", "{", "}", "&a ", "*a", "#", "\"", " ", "---\n",
    "? ", "!!str ", "2147483648", "-0", "line", "corner", "frontier", ",,"};

std::string ReadFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// One to three random edits of `input`; half of them replace a whole field
// (most other edits make a row unreadable, which tests less).
std::string Mutate(std::string input, std::mt19937_64* rng) {
  auto uniform = [&](std::size_t n) { return n == 0 ? 0 : static_cast<std::size_t>((*rng)() % n); };
  const int edits = 1 + static_cast<int>(uniform(3));
  for (int e = 0; e < edits; ++e) {
    const std::size_t at = uniform(input.size() + 1);
    switch (uniform(12)) {
      case 0:  // a byte changed
        if (!input.empty()) input[std::min(at, input.size() - 1)] = static_cast<char>(uniform(256));
        break;
      case 1:  // a piece inserted
        input.insert(at, kPieces[uniform(kPieces.size())]);
        break;
      case 2:  // a span deleted
        input.erase(at, 1 + uniform(16));
        break;
      case 3:  // cut short (a full disk, a killed writer)
        input.resize(at);
        break;
      case 4: {  // a span repeated
        const std::size_t length = uniform(std::min<std::size_t>(64, input.size() - at) + 1);
        input.insert(at, input.substr(at, length));
        break;
      }
      case 5:  // some bytes replaced by a piece
        input.replace(at, std::min<std::size_t>(1 + uniform(8), input.size() - at),
                      kPieces[uniform(kPieces.size())]);
        break;
      default: {  // the whole field (between separators) around `at` replaced by a piece
        const std::size_t begin = at == 0 ? 0 : input.find_last_of(",\n:", at - 1);
        const std::size_t start = begin == std::string::npos || at == 0 ? 0 : begin + 1;
        const std::size_t end = std::min(input.find_first_of(",\n", start), input.size());
        input.replace(start, end - start, kPieces[uniform(kPieces.size())]);
        break;
      }
    }
  }
  return input;
}

// Printable form of an input for a failure message.
std::string Escaped(const std::string& input) {
  std::string text;
  for (const char c : input.substr(0, 400)) {
    if (c == '\n') {
      text += "\\n";
    } else if (c >= 32 && c < 127) {
      text += c;
    } else {
      text += "\\x" + std::to_string(static_cast<unsigned char>(c));
    }
  }
  return text;
}

class MutationTest : public ::testing::TestWithParam<const char*> {};

TEST_P(MutationTest, EveryMutantIsReadOrRefusedWithAnError) {
  const Target& target = FindTarget(GetParam());
  const fs::path corpus = fs::path(MJSLAM_SOURCE_DIR) / "fuzz" / "corpus" / target.name;
  std::vector<fs::path> seeds;
  for (const fs::directory_entry& entry : fs::directory_iterator(corpus)) seeds.push_back(entry.path());
  std::sort(seeds.begin(), seeds.end());
  ASSERT_FALSE(seeds.empty()) << corpus;
  const std::string scratch = (fs::temp_directory_path() / ("mjslam_mutation_" + std::string(target.name) +
                                                           "_" + std::to_string(::getpid())))
                                  .string();
  std::mt19937_64 rng(kSeed);
  int failures = 0;
  int inputs = 0;
  for (const fs::path& seed : seeds) {
    const std::string original = ReadFile(seed);
    const int mutants = MutantsPerSeed();
    for (int m = 0; m <= mutants && failures < 5; ++m) {
      const std::string input = m == 0 ? original : Mutate(original, &rng);
      ++inputs;
      try {
        target.read(input, scratch);
      } catch (const std::exception& error) {
        ++failures;
        ADD_FAILURE() << target.name << ": " << seed.filename() << " mutant " << m << " (seed "
                      << kSeed << "): " << error.what() << "\ninput: " << Escaped(input);
      }
    }
  }
  fs::remove(scratch);
  std::printf("%s: %d inputs from %zu seeds, %d failures\n", target.name, inputs, seeds.size(),
              failures);
}

INSTANTIATE_TEST_SUITE_P(Targets, MutationTest,
                         ::testing::Values("config", "trajectory", "scans", "map", "explorer",
                                           "import", "campaign", "world"));

}  // namespace
}  // namespace mjslam::fuzz
