#include "config/config.h"

#include <gtest/gtest.h>

#include <sys/resource.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <variant>
#include <vector>

#include "tests/config/toy_params.h"

namespace mjslam::config {
namespace {

using testing::ToyParams;

// The message of the ConfigError that loading `yaml` (named "x.yaml") throws.
std::string ErrorOf(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
  try {
    LoadConfigString<ToyParams>(yaml, "x.yaml", overrides);
  } catch (const ConfigError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no ConfigError for:\n" << yaml;
  return {};
}

::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "'" << part << "' not in:\n" << text;
}

// Local classes cannot have member templates: this one lives here.
struct SpecialToyParams {
  int offset = 0;
  double limit = 0.0;
  double low = 0.0;
  bool flag = false;
  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(offset));
    a->Visit(MJSLAM_NVP(limit));
    a->Visit(MJSLAM_NVP(low));
    a->Visit(MJSLAM_NVP(flag));
  }
};

std::size_t LineCount(const std::string& text) {
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
}

TEST(ConfigTest, AbsentKeysKeepDefaults) {
  const ToyParams params = LoadConfigString<ToyParams>(
      "rate_hz: 20\n"
      "laser:\n"
      "  beam_count: 90\n",
      "x.yaml");
  const ToyParams defaults;
  EXPECT_EQ(params.rate_hz, 20.0);
  EXPECT_EQ(params.laser.beam_count, 90);
  EXPECT_EQ(params.min_range_m, defaults.min_range_m);
  EXPECT_EQ(params.laser.range_noise_std_m, defaults.laser.range_noise_std_m);
  EXPECT_EQ(params.laser.mode, defaults.laser.mode);
  EXPECT_EQ(params.laser.gains, defaults.laser.gains);
  EXPECT_EQ(params.laser.inner.gain, defaults.laser.inner.gain);
}

TEST(ConfigTest, EmptyTextGivesDefaults) {
  const ToyParams defaults;
  for (const std::string text : {"", "\n", "# only a comment\n", "---\n"}) {
    const ToyParams params = LoadConfigString<ToyParams>(text, "x.yaml");
    EXPECT_EQ(ToYaml(params), ToYaml(defaults)) << "text: '" << text << "'";
  }
}

TEST(ConfigTest, NullStructKeepsDefaults) {
  const ToyParams params = LoadConfigString<ToyParams>("laser:\nrate_hz: 3\n", "x.yaml");
  EXPECT_EQ(params.laser.beam_count, 181);
  EXPECT_EQ(params.rate_hz, 3.0);
}

TEST(ConfigTest, ReadsEverySupportedType) {
  const ToyParams params = LoadConfigString<ToyParams>(
      "rate_hz: 1e-9\n"
      "min_range_m: -.5\n"
      "max_range_m: +12\n"
      "laser:\n"
      "  range_noise_std_m: 0.1\n"
      "  beam_count: -7\n"
      "  enabled: false\n"
      "  seed: 18446744073709551615\n"
      "  mode: \"noisy\"\n"
      "  gains: [0.5, 3]\n"
      "  waypoints:\n"
      "    - [0, 0]\n"
      "    - [1.5, -2]\n"
      "  inner:\n"
      "    gain: 1\n"
      "    offset_m: [1, 2, 3.25]\n",
      "x.yaml", {"laser.beam_count=5"});  // -7 would fail Validate
  EXPECT_EQ(params.rate_hz, 1e-9);
  EXPECT_EQ(params.min_range_m, -0.5);
  EXPECT_EQ(params.max_range_m, 12.0);
  EXPECT_EQ(params.laser.range_noise_std_m, 0.1);
  EXPECT_EQ(params.laser.beam_count, 5);
  EXPECT_FALSE(params.laser.enabled);
  EXPECT_EQ(params.laser.seed, std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(params.laser.mode, "noisy");
  EXPECT_EQ(params.laser.gains, (std::vector<double>{0.5, 3.0}));
  ASSERT_EQ(params.laser.waypoints.size(), 2u);
  EXPECT_EQ(params.laser.waypoints[1][0], 1.5);
  EXPECT_EQ(params.laser.waypoints[1][1], -2.0);
  EXPECT_EQ(params.laser.inner.gain, 1.0);
  EXPECT_EQ(params.laser.inner.offset_m, (std::array<double, 3>{1.0, 2.0, 3.25}));
}

TEST(ConfigTest, ReadsNegativeIntAndSpecialDoubles) {
  const SpecialToyParams local = LoadConfigString<SpecialToyParams>(
      "offset: -2147483648\nlimit: .inf\nlow: -.Inf\nflag: True\n", "x.yaml");
  EXPECT_EQ(local.offset, std::numeric_limits<int>::min());
  EXPECT_EQ(local.limit, std::numeric_limits<double>::infinity());
  EXPECT_EQ(local.low, -std::numeric_limits<double>::infinity());
  EXPECT_TRUE(local.flag);
}

// yaml-cpp says "illegal map value" for some tab indentations; the error
// must say what is wrong.
TEST(ConfigTest, TabIndentationErrorSaysTab) {
  for (const char* text : {"laser:\n\tgain: 1.0\n", "laser:\n  gain: 1.0\n\toffset_m: [1, 2, 3]\n"}) {
    const std::string message = ErrorOf(text);
    EXPECT_TRUE(Contains(message, "indented with a tab")) << message;
    EXPECT_EQ(LineCount(message), 1u) << message;
  }
}

// `.inf` is YAML for infinity, and no rate, size or time.
TEST(ConfigTest, InfinityIsRefusedForAPositiveKey) {
  const std::string message = ErrorOf("rate_hz: .inf\n");
  EXPECT_TRUE(Contains(message, "x.yaml:1:10: rate_hz: expected a finite value > 0 (got inf)"))
      << message;
}

TEST(ConfigTest, UnknownKeyListsKnownKeysWithLineCol) {
  const std::string message = ErrorOf(
      "rate_hz: 1\n"
      "laser:\n"
      "  rnage_noise_std_m: 1\n");
  EXPECT_TRUE(Contains(message, "x.yaml:3:3: laser.rnage_noise_std_m: unknown key"));
  EXPECT_TRUE(Contains(message, "did you mean 'range_noise_std_m'?"));
  EXPECT_TRUE(Contains(message,
                       "(known keys of laser: range_noise_std_m, beam_count, enabled, seed, "
                       "mode, gains, waypoints, inner)"));
  EXPECT_EQ(LineCount(message), 1u) << message;
}

TEST(ConfigTest, UnknownTopLevelKeyListsTopLevelKeys) {
  const std::string message = ErrorOf("rate_hz: 1\nsimulator: {}\n");
  EXPECT_TRUE(Contains(message, "x.yaml:2:1: simulator: unknown key (known keys: rate_hz, "
                                "min_range_m, max_range_m, laser)"));
}

TEST(ConfigTest, UnknownKeySuggestsOnlyCloseMatches) {
  // A swap of neighbours is one edit; five letters allow one edit.
  EXPECT_TRUE(Contains(ErrorOf("lasre: {}\n"), "lasre: unknown key, did you mean 'laser'? (known"));
  // Two edits away from "laser" in four letters: no suggestion.
  EXPECT_TRUE(Contains(ErrorOf("case: 1\n"), "case: unknown key (known keys: rate_hz,"));
}

TEST(ConfigTest, DuplicateKeyRejected) {
  const std::string message = ErrorOf(
      "rate_hz: 1\n"
      "laser:\n"
      "  beam_count: 3\n"
      "  beam_count: 4\n"
      "rate_hz: 2\n");
  EXPECT_TRUE(Contains(message, "x.yaml:4:3: laser.beam_count: duplicate key (first given at "
                                "x.yaml:3:3)"));
  EXPECT_TRUE(Contains(message, "x.yaml:5:1: rate_hz: duplicate key (first given at x.yaml:1:1)"));
  EXPECT_EQ(LineCount(message), 2u) << message;
}

TEST(ConfigTest, WrongTypesRejectedWithMark) {
  struct Case {
    std::string yaml;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {"rate_hz: abc\n", "x.yaml:1:10: rate_hz: expected a number (got abc)"},
      {"rate_hz: \"1.5\"\n", "x.yaml:1:10: rate_hz: expected an unquoted number (got \"1.5\")"},
      {"rate_hz: inf\n", "x.yaml:1:10: rate_hz: expected a number (got inf)"},
      {"rate_hz: 1e999\n", "x.yaml:1:10: rate_hz: expected a number within the range of a double "
                           "(got 1e999)"},
      {"rate_hz:\n", "x.yaml:1:1: rate_hz: expected a number (got null)"},
      {"rate_hz: {a: 1}\n", "x.yaml:1:10: rate_hz: expected a number (got a map)"},
      {"laser:\n  beam_count: 1.5\n", "x.yaml:2:15: laser.beam_count: expected an integer (got 1.5)"},
      {"laser:\n  beam_count: 3000000000\n",
       "laser.beam_count: expected an integer in [-2147483648, 2147483647] (got 3000000000)"},
      {"laser:\n  seed: -3\n", "x.yaml:2:9: laser.seed: expected a non-negative integer (got -3)"},
      {"laser:\n  enabled: yes\n", "x.yaml:2:12: laser.enabled: expected true or false (got yes)"},
      {"laser:\n  mode: [a]\n", "x.yaml:2:9: laser.mode: expected a string (got a sequence of 1 item)"},
      {"laser:\n  gains: 5\n",
       "x.yaml:2:10: laser.gains: expected a sequence of numbers (got 5)"},
      {"laser:\n  gains: [1, x, 2]\n", "x.yaml:2:14: laser.gains[1]: expected a number (got x)"},
      {"laser:\n  waypoints: [[0, 0], [1]]\n",
       "x.yaml:2:23: laser.waypoints[1]: expected a sequence of 2 numbers (got a sequence of 1 "
       "item)"},
      {"laser:\n  waypoints:\n    - [0, 0]\n    - [1, b]\n",
       "x.yaml:4:11: laser.waypoints[1][1]: expected a number (got b)"},
      {"laser:\n  inner:\n    offset_m: [1, 2]\n",
       "x.yaml:3:15: laser.inner.offset_m: expected a sequence of 3 numbers (got a sequence of 2 "
       "items)"},
      {"laser: 5\n", "x.yaml:1:8: laser: expected a map of keys (got 5)"},
      {"- 1\n- 2\n", "x.yaml:1:1: expected a map of keys at the top level (got a sequence of 2 items)"},
  };
  for (const Case& c : cases) {
    const std::string message = ErrorOf(c.yaml);
    EXPECT_TRUE(Contains(message, c.expected)) << "yaml:\n" << c.yaml;
    EXPECT_EQ(LineCount(message), 1u) << message;
  }
}

TEST(ConfigTest, WrongTypeLeavesDefaultAndOtherKeysRead) {
  // The bad element keeps the whole vector at its default.
  const std::string message = ErrorOf("laser:\n  gains: [1, x]\n  beam_count: 0\n");
  EXPECT_TRUE(Contains(message, "laser.gains[1]: expected a number (got x)"));
  EXPECT_TRUE(Contains(message, "x.yaml:3:15: laser.beam_count: expected a value > 0 (got 0)"));
}

TEST(ConfigTest, OutOfRangeFromValidatePointsAtValue) {
  EXPECT_TRUE(Contains(ErrorOf("laser:\n  range_noise_std_m: -1\n"),
                       "x.yaml:2:22: laser.range_noise_std_m: expected a value >= 0 (got -1)"));
  EXPECT_TRUE(Contains(ErrorOf("laser:\n  inner:\n    gain: 2\n"),
                       "x.yaml:3:11: laser.inner.gain: expected a value in [0, 1] (got 2)"));
  EXPECT_TRUE(Contains(ErrorOf("laser:\n  mode: fast\n"),
                       "x.yaml:2:9: laser.mode: expected one of exact, noisy (got fast)"));
  // An element key from Validate ("gains[1]") maps to that element.
  EXPECT_TRUE(Contains(ErrorOf("laser:\n  gains: [1, -2]\n"),
                       "x.yaml:2:14: laser.gains[1]: expected a value > 0 (got -2)"));
}

TEST(ConfigTest, ProblemWithDefaultValueNamesFileOnly) {
  // min_range_m keeps its default (0.1), which is now >= max_range_m.
  const std::string message = ErrorOf("max_range_m: 0.05\n");
  EXPECT_EQ(message, "x.yaml: min_range_m: expected a value < max_range_m (got 0.1)");
}

TEST(ConfigTest, ReportsEveryProblemInOneThrow) {
  try {
    LoadConfigString<ToyParams>(
        "rate_hz: -1\n"
        "bogus: 1\n"
        "laser:\n"
        "  beam_count: x\n"
        "  seed: 1\n"
        "  seed: 2\n"
        "  range_noise_std_m: -0.5\n",
        "x.yaml", {"laser.inner.gain=7"});
    FAIL() << "no ConfigError";
  } catch (const ConfigError& error) {
    const std::string message = error.what();
    EXPECT_EQ(error.problems().size(), 6u) << message;
    EXPECT_EQ(LineCount(message), 6u) << message;
    // Text order, then the --set option.
    EXPECT_EQ(error.problems().front().key, "rate_hz");
    EXPECT_EQ(error.problems().back().key, "laser.inner.gain");
    EXPECT_TRUE(Contains(message, "x.yaml:2:1: bogus: unknown key"));
    EXPECT_TRUE(Contains(message, "x.yaml:4:15: laser.beam_count: expected an integer (got x)"));
    EXPECT_TRUE(Contains(message, "x.yaml:6:3: laser.seed: duplicate key"));
    EXPECT_TRUE(Contains(message, "x.yaml:1:10: rate_hz: expected a value > 0 (got -1)"));
    EXPECT_TRUE(Contains(message,
                         "x.yaml:7:22: laser.range_noise_std_m: expected a value >= 0 (got -0.5)"));
    EXPECT_TRUE(Contains(message, "--set laser.inner.gain=7: laser.inner.gain: expected a value in "
                                  "[0, 1] (got 7)"));
  }
}

TEST(ConfigTest, ConfigErrorIsRuntimeError) {
  EXPECT_THROW(LoadConfigString<ToyParams>("rate_hz: 0\n", "x.yaml"), std::runtime_error);
}

TEST(ConfigTest, OverrideSetsScalarNestedAndFlowSequence) {
  const ToyParams params = LoadConfigString<ToyParams>(
      "rate_hz: 1\nlaser:\n  range_noise_std_m: 0.5\n  beam_count: 7\n", "x.yaml",
      {"rate_hz=5", "laser.range_noise_std_m=0", "laser.waypoints=[[0,0],[1,2]]",
       "laser.mode=noisy", "laser.inner.offset_m=[1, 2, 3]"});
  EXPECT_EQ(params.rate_hz, 5.0);
  EXPECT_EQ(params.laser.range_noise_std_m, 0.0);
  EXPECT_EQ(params.laser.beam_count, 7);  // untouched file value
  ASSERT_EQ(params.laser.waypoints.size(), 2u);
  EXPECT_EQ(params.laser.waypoints[1][0], 1.0);
  EXPECT_EQ(params.laser.waypoints[1][1], 2.0);
  EXPECT_EQ(params.laser.mode, "noisy");
  EXPECT_EQ(params.laser.inner.offset_m, (std::array<double, 3>{1.0, 2.0, 3.0}));
}

TEST(ConfigTest, LaterOverrideWinsAndMapOverrideMerges) {
  const ToyParams params = LoadConfigString<ToyParams>(
      "laser:\n  range_noise_std_m: 0.5\n  beam_count: 7\n", "x.yaml",
      {"rate_hz=5", "rate_hz=6", "laser={beam_count: 9}", "laser.inner={gain: 0.25}"});
  EXPECT_EQ(params.rate_hz, 6.0);
  EXPECT_EQ(params.laser.beam_count, 9);
  EXPECT_EQ(params.laser.range_noise_std_m, 0.5);  // kept by the merge
  EXPECT_EQ(params.laser.inner.gain, 0.25);
}

TEST(ConfigTest, OverrideOfUnknownKeyNamesSetAndKey) {
  const std::string message = ErrorOf("laser:\n  beam_count: 7\n", {"laser.beam_cuont=3"});
  EXPECT_TRUE(Contains(message, "--set laser.beam_cuont=3: laser.beam_cuont: unknown key, did you "
                                "mean 'beam_count'? (known keys of laser:"));
  EXPECT_TRUE(Contains(ErrorOf("", {"nothing.here=1"}),
                       "--set nothing.here=1: nothing: unknown key (known keys: rate_hz,"));
}

TEST(ConfigTest, OverrideWithBadValueNamesSetAndKey) {
  EXPECT_EQ(ErrorOf("", {"laser.beam_count=abc"}),
            "--set laser.beam_count=abc: laser.beam_count: expected an integer (got abc)");
  EXPECT_EQ(ErrorOf("laser:\n  range_noise_std_m: 1\n", {"laser.range_noise_std_m=-1"}),
            "--set laser.range_noise_std_m=-1: laser.range_noise_std_m: expected a value >= 0 "
            "(got -1)");
  EXPECT_TRUE(Contains(ErrorOf("", {"laser.gains=[1,"}),
                       "--set laser.gains=[1,: laser.gains: invalid YAML value: "));
  EXPECT_EQ(ErrorOf("", {"rate_hz"}), "--set rate_hz: expected --set dotted.key=value");
  EXPECT_EQ(ErrorOf("", {"laser..seed=1"}),
            "--set laser..seed=1: laser..seed: expected a dotted key like laser.range_noise_std_m");
  EXPECT_EQ(ErrorOf("", {"laser.waypoints=[[0,0],[1]]"}),
            "--set laser.waypoints=[[0,0],[1]]: laser.waypoints[1]: expected a sequence of 2 "
            "numbers (got a sequence of 1 item)");
}

TEST(ConfigTest, YamlSyntaxErrorHasLineCol) {
  const std::string message = ErrorOf("rate_hz: 1\nlaser: [1,\nmode: 2\n");
  // yaml-cpp reports the unclosed flow sequence at the end of the text.
  EXPECT_TRUE(Contains(message, "x.yaml:4:1: YAML syntax error: end of sequence flow not found"));
  EXPECT_TRUE(Contains(ErrorOf("laser:\n  seed: 1\n    x: 2\n"), "x.yaml:3:6: YAML syntax error: "));
}

TEST(ConfigTest, MoreThanOneDocumentRejected) {
  EXPECT_TRUE(Contains(ErrorOf("rate_hz: 1\n---\nrate_hz: 2\n"),
                       "x.yaml:2:1: expected one YAML document (a second one starts here)"));
}

// In a child process with 1 GiB of address space: exits 0 when loading `yaml`
// with `overrides` fails with a message containing `expected`, else 1. It
// leaves with _Exit: exit handlers may need address space the limit no longer
// grants (LeakSanitizer's final check under scripts/sanitize.sh could not map
// its stack and turned a passing case into exit status 1).
[[noreturn]] void ExitWithErrorCheck(const std::string& yaml,
                                     const std::vector<std::string>& overrides,
                                     const std::string& expected) {
  const rlimit limit{rlim_t{1} << 30, rlim_t{1} << 30};
  setrlimit(RLIMIT_AS, &limit);
  const std::string message = ErrorOf(yaml, overrides);
  std::fprintf(stderr, "%s\n", message.c_str());
  std::fflush(stderr);
  std::_Exit(message.find(expected) != std::string::npos ? 0 : 1);
}

// yaml-cpp 0.7.0's LoadAll never returns on a document that starts with a
// flow indicator (it allocated until the machine ran out of memory). Each
// case runs in a child process with 1 GiB of address space, so a regression
// fails here (killed or timed out) instead of taking the machine down.
TEST(ConfigTest, DocumentStartingWithCommaIsSyntaxErrorInBoundedMemory) {
  struct Case {
    std::string yaml;
    std::vector<std::string> overrides;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {",", {}, "x.yaml:1:1: YAML syntax error: a document cannot start with ','"},
      {",a: 1\n", {}, "x.yaml:1:1: YAML syntax error: a document cannot start with ','"},
      {"rate_hz: 1\n---\n,\n", {}, "x.yaml:2:1: expected one YAML document"},
      {"", {"rate_hz=,"}, "--set rate_hz=,: rate_hz: invalid YAML value: "},
  };
  for (const Case& c : cases) {
    EXPECT_EXIT(ExitWithErrorCheck(c.yaml, c.overrides, c.expected), ::testing::ExitedWithCode(0),
                "")
        << "yaml: '" << c.yaml << "', expected: " << c.expected;
  }
}

TEST(ConfigTest, RecursiveAliasRejectedNotFollowed) {
  EXPECT_TRUE(Contains(ErrorOf("laser: &x [*x]\n"), "recursive alias"));
}

TEST(ConfigTest, MissingFileIsConfigError) {
  const std::string path = "/nonexistent/mjslam/x.yaml";
  try {
    LoadConfigFile<ToyParams>(path);
    FAIL() << "no ConfigError";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()),
              path + ": cannot read config file (No such file or directory)");
  }
  EXPECT_THROW(LoadConfigFile<ToyParams>(::testing::TempDir()), ConfigError);  // a directory
}

TEST(ConfigTest, LoadsFileAndNamesItInMessages) {
  const std::string path = ::testing::TempDir() + "/mjslam_config_test_run.yaml";
  {
    std::ofstream out(path);
    out << "rate_hz: 4\nlaser:\n  range_noise_std_m: 0.25\n";
  }
  const ToyParams params = LoadConfigFile<ToyParams>(path, {"laser.seed=7"});
  EXPECT_EQ(params.rate_hz, 4.0);
  EXPECT_EQ(params.laser.range_noise_std_m, 0.25);
  EXPECT_EQ(params.laser.seed, 7u);
  try {
    LoadConfigFile<ToyParams>(path, {"laser.range_noise_std_m=x"});
    FAIL() << "no ConfigError";
  } catch (const ConfigError& error) {
    EXPECT_TRUE(Contains(error.what(), "--set laser.range_noise_std_m=x: laser.range_noise_std_m"));
  }
  {
    std::ofstream out(path);
    out << "rate_hz: 4\nlaser:\n  range_noise_std_m: -0.25\n";
  }
  try {
    LoadConfigFile<ToyParams>(path);
    FAIL() << "no ConfigError";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()),
              path + ":3:22: laser.range_noise_std_m: expected a value >= 0 (got -0.25)");
  }
  std::filesystem::remove(path);
}

// Writes `text` to `name` in a fresh folder of its own under the test's
// temporary folder and returns the path.
std::string WriteFile(const std::string& folder, const std::string& name,
                      const std::string& text) {
  const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / folder;
  std::filesystem::create_directories(dir);
  const std::string path = (dir / name).string();
  std::ofstream(path) << text;
  return path;
}

TEST(ConfigBaseTest, FileStatesWhatDiffersFromItsBaseChain) {
  WriteFile("bases", "a.yaml", "rate_hz: 4\nlaser:\n  beam_count: 5\n  mode: noisy\n");
  WriteFile("bases", "b.yaml", "base: a.yaml\nlaser:\n  beam_count: 7\n");
  const std::string c = WriteFile("bases", "c.yaml", "base: b.yaml\nmin_range_m: 0.5\n");
  const ToyParams params = LoadConfigFile<ToyParams>(c, {"laser.seed=3"});
  EXPECT_EQ(params.rate_hz, 4.0);               // from a.yaml
  EXPECT_EQ(params.laser.mode, "noisy");        // a.yaml, under b.yaml's laser map
  EXPECT_EQ(params.laser.beam_count, 7);        // b.yaml over a.yaml
  EXPECT_EQ(params.min_range_m, 0.5);           // c.yaml
  EXPECT_EQ(params.laser.seed, 3u);             // --set over all
  EXPECT_EQ(params.max_range_m, 30.0);          // the default
}

TEST(ConfigBaseTest, ProblemsNameTheFileAndLineThatSetTheValue) {
  const std::string a = WriteFile("bases_marks", "a.yaml", "rate_hz: 4\nlaser:\n  beam_count: -5\n");
  const std::string b = WriteFile("bases_marks", "b.yaml", "base: a.yaml\nrate_hz: 2\n");
  try {
    LoadConfigFile<ToyParams>(b);
    FAIL() << "no ConfigError";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()),
              a + ":3:15: laser.beam_count: expected a value > 0 (got -5)");
  }
  internal::MarkTable marks;
  WriteFile("bases_marks", "a.yaml", "rate_hz: 4\n");
  LoadConfigFile<ToyParams>(b, {}, &marks);
  EXPECT_EQ(marks.Find("rate_hz", b).source, b);
  EXPECT_EQ(marks.Find("max_range_m", b).source, b);  // a default names the file read
}

TEST(ConfigBaseTest, MissingBaseCycleAndBadValueAreProblemsOnTheBaseLine) {
  const std::string missing = WriteFile("bases_bad", "m.yaml", "rate_hz: 2\nbase: none.yaml\n");
  EXPECT_TRUE(Contains(
      [&] {
        try {
          LoadConfigFile<ToyParams>(missing);
        } catch (const ConfigError& error) {
          return std::string(error.what());
        }
        return std::string();
      }(),
      missing + ":2:7: base: cannot read config file (No such file or directory): '"));

  WriteFile("bases_bad", "x.yaml", "base: y.yaml\n");
  const std::string y = WriteFile("bases_bad", "y.yaml", "base: ./x.yaml\n");
  try {
    LoadConfigFile<ToyParams>(y);
    FAIL() << "no ConfigError for a cycle";
  } catch (const ConfigError& error) {
    EXPECT_TRUE(Contains(error.what(), "is this file or one of its bases (a cycle)"));
  }
  EXPECT_TRUE(Contains(ErrorOf("base: [a, b]\n"), "x.yaml:1:7: base: expected the path of a config file"));
}

TEST(ConfigBaseTest, MapOfAnotherKindReplacesTheBasesMap) {
  WriteFile("bases_kind", "a.yaml", "model:\n  kind: one\n  p: 1\n  q: 2\n");
  const std::string same =
      WriteFile("bases_kind", "same.yaml", "base: a.yaml\nmodel:\n  p: 3\n");
  const std::string other =
      WriteFile("bases_kind", "other.yaml", "base: a.yaml\nmodel:\n  kind: two\n  r: 4\n");
  const auto keys = [](const std::string& path) {
    std::vector<ConfigProblem> problems;
    const ConfigNode root =
        internal::ReadWithBases(internal::ReadTextFile(path), path, &problems);
    EXPECT_TRUE(problems.empty());
    std::string text;
    for (const ConfigEntry& entry : root.entries.at(0).value.entries) {
      text += entry.key + "=" + entry.value.scalar + " ";
    }
    return text;
  };
  EXPECT_EQ(keys(same), "p=3 kind=one q=2 ");
  EXPECT_EQ(keys(other), "kind=two r=4 ");
  // The same rule for --set: a map of another kind replaces.
  std::vector<ConfigProblem> problems;
  ConfigNode root = internal::ReadWithBases(internal::ReadTextFile(same), same, &problems);
  internal::ApplyOverrides({"model={kind: two, r: 5}"}, &root, &problems);
  ASSERT_TRUE(problems.empty());
  ASSERT_EQ(root.entries.at(0).value.entries.size(), 2u);
  EXPECT_EQ(root.entries.at(0).value.entries[1].value.scalar, "5");
}

// The message of the ConfigError that loading `yaml` as ChoiceToyParams throws.
std::string ChoiceErrorOf(const std::string& yaml, const std::vector<std::string>& overrides = {}) {
  try {
    LoadConfigString<testing::ChoiceToyParams>(yaml, "x.yaml", overrides);
  } catch (const ConfigError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no ConfigError for:\n" << yaml;
  return {};
}

TEST(ConfigChoiceTest, KindPicksTheAlternativeAndAbsentKindKeepsTheCurrentOne) {
  using testing::ChoiceToyParams;
  using testing::CircleToyModel;
  using testing::LineToyModel;
  const auto circle = LoadConfigString<ChoiceToyParams>(
      "model:\n  kind: circle\n  radius_m: 3\n  centre: {x_m: 1}\n", "x.yaml");
  ASSERT_TRUE(std::holds_alternative<CircleToyModel>(circle.model));
  EXPECT_EQ(std::get<CircleToyModel>(circle.model).radius_m, 3.0);
  EXPECT_EQ(std::get<CircleToyModel>(circle.model).centre.x_m, 1.0);
  EXPECT_EQ(std::get<CircleToyModel>(circle.model).inner.gain, 0.5);  // the default
  // No kind: the current alternative (here the default, line) is read.
  const auto line = LoadConfigString<ChoiceToyParams>("model:\n  slope: 2\n", "x.yaml");
  ASSERT_TRUE(std::holds_alternative<LineToyModel>(line.model));
  EXPECT_EQ(std::get<LineToyModel>(line.model).slope, 2.0);
  EXPECT_TRUE(std::holds_alternative<LineToyModel>(
      LoadConfigString<ChoiceToyParams>("model:\n", "x.yaml").model));
  // A quoted kind (as ToYaml writes it) is the same kind.
  EXPECT_TRUE(std::holds_alternative<CircleToyModel>(
      LoadConfigString<ChoiceToyParams>("model: {kind: \"circle\"}\n", "x.yaml").model));
}

TEST(ConfigChoiceTest, KeyOfAnotherKindNamesFileLineKeyAndBothKinds) {
  EXPECT_EQ(ChoiceErrorOf("rate_hz: 2\nmodel:\n  kind: circle\n  slope: 2\n"),
            "x.yaml:4:3: model.slope: a key of kind 'line', not of kind 'circle' "
            "(known keys of model: kind, radius_m, inner, centre)");
  // In a nested map of the other kind too; a key of no kind stays unknown.
  const std::string nested =
      ChoiceErrorOf("model:\n  kind: line\n  centre: {x_m: 1}\n  inner: {gian: 1}\n");
  EXPECT_TRUE(Contains(nested, "x.yaml:3:3: model.centre: a key of kind 'circle', not of kind 'line'"));
  EXPECT_TRUE(Contains(nested, "x.yaml:4:11: model.inner.gian: unknown key, did you mean 'gain'?"));
  // Without a kind in the map the message says whose kind it is.
  EXPECT_TRUE(Contains(ChoiceErrorOf("model:\n  radius_m: 1\n"),
                       "x.yaml:2:3: model.radius_m: a key of kind 'circle', not of kind 'line' "
                       "(no kind given here: the base's or the default)"));
}

TEST(ConfigChoiceTest, RetiredKeysNameTheKeyThatReplacedThem) {
  // At the top level and inside a choice's alternative, with the note.
  const std::string what = ChoiceErrorOf("line_slope: 2\nmodel:\n  gradient: 3\n");
  EXPECT_TRUE(Contains(what, "x.yaml:1:1: line_slope: a retired key, now model.slope "
                             "(with model.kind: line)"))
      << what;
  EXPECT_TRUE(Contains(what + "\n", "x.yaml:3:3: model.gradient: a retired key, now model.slope\n"))
      << what;
}

TEST(ConfigChoiceTest, BadKindValuesAndValidationProblemsPointAtTheirText) {
  EXPECT_EQ(ChoiceErrorOf("model:\n  kind: square\n  slope: 2\n"),
            "x.yaml:2:9: model.kind: expected line or circle (got square)");
  EXPECT_EQ(ChoiceErrorOf("model:\n  kind: [line]\n"),
            "x.yaml:2:9: model.kind: expected line or circle (got a sequence of 1 item)");
  EXPECT_EQ(ChoiceErrorOf("model: circle\n"),
            "x.yaml:1:8: model: expected a map with a kind (got circle)");
  EXPECT_EQ(ChoiceErrorOf("model:\n  kind: circle\n  radius_m: -1\n"),
            "x.yaml:3:13: model.radius_m: expected a value > 0 (got -1)");
  EXPECT_TRUE(Contains(ChoiceErrorOf("model:\n  kind: line\n  kind: circle\n"),
                       "x.yaml:3:3: model.kind: duplicate key"));
}

TEST(ConfigChoiceTest, WritesTheKindFirstAndLoadsBackIdentically) {
  testing::ChoiceToyParams params;
  testing::CircleToyModel circle;
  circle.radius_m = 0.25;
  circle.centre.y_m = -1.5;
  params.model = circle;
  const std::string text = ToYaml(params);
  EXPECT_TRUE(Contains(text, "model:\n  kind: \"circle\"\n  radius_m: 0.25\n")) << text;
  const auto again = LoadConfigString<testing::ChoiceToyParams>(text, "resolved");
  EXPECT_EQ(ToYaml(again), text);
  EXPECT_EQ(std::get<testing::CircleToyModel>(again.model).centre.y_m, -1.5);
}

TEST(ConfigChoiceTest, SettingAnotherKindDropsTheKeysOfTheOldOne) {
  using testing::ChoiceToyParams;
  using testing::CircleToyModel;
  const std::string yaml = "model:\n  kind: line\n  slope: 3\n  inner: {gain: 0.25}\n";
  // --set model.kind=circle is --set model={kind: circle}: every key of the
  // line goes (its inner.gain too: a different choice starts from defaults).
  for (const std::string option : {"model.kind=circle", "model={kind: circle}"}) {
    const auto params = LoadConfigString<ChoiceToyParams>(yaml, "x.yaml", {option});
    ASSERT_TRUE(std::holds_alternative<CircleToyModel>(params.model)) << option;
    EXPECT_EQ(std::get<CircleToyModel>(params.model).inner.gain, 0.5) << option;
  }
  // The same kind again keeps the keys; then a key of the new kind applies.
  const auto same = LoadConfigString<ChoiceToyParams>(yaml, "x.yaml", {"model.kind=line"});
  EXPECT_EQ(std::get<testing::LineToyModel>(same.model).slope, 3.0);
  const auto set = LoadConfigString<ChoiceToyParams>(yaml, "x.yaml",
                                                     {"model.kind=circle", "model.radius_m=4"});
  EXPECT_EQ(std::get<CircleToyModel>(set.model).radius_m, 4.0);
  // A key of the old kind after the switch names both kinds and the option.
  EXPECT_TRUE(Contains(ChoiceErrorOf(yaml, {"model.kind=circle", "model.slope=1"}),
                       "--set model.slope=1: model.slope: a key of kind 'line', not of kind 'circle'"));
}

TEST(ConfigChoiceTest, AFileOfAnotherKindThanItsBaseTakesNothingFromTheBasesChoice) {
  WriteFile("bases_choice", "a.yaml", "rate_hz: 4\nmodel:\n  kind: line\n  slope: 3\n");
  const std::string same =
      WriteFile("bases_choice", "same.yaml", "base: a.yaml\nmodel:\n  inner: {gain: 0.25}\n");
  const std::string other =
      WriteFile("bases_choice", "other.yaml", "base: a.yaml\nmodel:\n  kind: circle\n");
  const auto merged = LoadConfigFile<testing::ChoiceToyParams>(same);
  EXPECT_EQ(std::get<testing::LineToyModel>(merged.model).slope, 3.0);
  EXPECT_EQ(std::get<testing::LineToyModel>(merged.model).inner.gain, 0.25);
  const auto replaced = LoadConfigFile<testing::ChoiceToyParams>(other);
  EXPECT_EQ(replaced.rate_hz, 4.0);
  EXPECT_EQ(std::get<testing::CircleToyModel>(replaced.model).radius_m, 2.0);
}

}  // namespace
}  // namespace mjslam::config
