#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "config/config.h"
#include "tests/config/toy_params.h"

namespace mjslam::config {
namespace {

using testing::ToyParams;

// Bit-for-bit equality, so that -0.0 vs 0.0 or a last-bit difference fails.
bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

void ExpectSameBits(const std::vector<double>& a, const std::vector<double>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(SameBits(a[i], b[i])) << "item " << i << ": " << a[i] << " vs " << b[i];
  }
}

// Every field of a ToyParams as doubles, for a bitwise comparison.
std::vector<double> Doubles(const ToyParams& p) {
  std::vector<double> out = {p.rate_hz, p.min_range_m, p.max_range_m,
                             p.laser.range_noise_std_m, p.laser.inner.gain};
  out.insert(out.end(), p.laser.gains.begin(), p.laser.gains.end());
  for (const auto& w : p.laser.waypoints) out.insert(out.end(), w.begin(), w.end());
  out.insert(out.end(), p.laser.inner.offset_m.begin(), p.laser.inner.offset_m.end());
  return out;
}

// A struct without Validate, for strings that no real Params would accept.
struct StringToyParams {
  std::string text;
  std::vector<double> values{1.0};
  std::vector<std::array<double, 2>> pairs{{1.0, 2.0}};
  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(text));
    a->Visit(MJSLAM_NVP(values));
    a->Visit(MJSLAM_NVP(pairs));
  }
};

ToyParams Tricky() {
  ToyParams p;
  p.rate_hz = 0.1;
  p.min_range_m = 1e-9;
  p.max_range_m = 1.0 / 3.0;
  p.laser.range_noise_std_m = 5e-324;  // smallest subnormal
  p.laser.beam_count = std::numeric_limits<int>::max();
  p.laser.enabled = false;
  p.laser.seed = std::numeric_limits<std::uint64_t>::max();
  p.laser.mode = "noisy";
  p.laser.gains = {std::numeric_limits<double>::max(), 2.0, 1e21, 123456789.125,
                   0.30000000000000004, std::numeric_limits<double>::min()};
  p.laser.waypoints = {{-0.0, -1e-300}, {1e300, -2.5}};
  p.laser.inner.gain = 0.7;
  p.laser.inner.offset_m = {-0.1, 6.02214076e23, -3.0};
  return p;
}

TEST(ConfigRoundTripTest, ToYamlLoadsBackToIdenticalValues) {
  const ToyParams original = Tricky();
  const std::string yaml = ToYaml(original);
  ToyParams loaded;
  ASSERT_NO_THROW(loaded = LoadConfigString<ToyParams>(yaml, "config.yaml")) << yaml;
  ExpectSameBits(Doubles(loaded), Doubles(original));
  EXPECT_EQ(loaded.laser.beam_count, original.laser.beam_count);
  EXPECT_EQ(loaded.laser.enabled, original.laser.enabled);
  EXPECT_EQ(loaded.laser.seed, original.laser.seed);
  EXPECT_EQ(loaded.laser.mode, original.laser.mode);
  EXPECT_EQ(ToYaml(loaded), yaml);
}

TEST(ConfigRoundTripTest, DoublesWrittenShortestAndAsFloats) {
  const std::string yaml = ToYaml(Tricky());
  EXPECT_NE(yaml.find("rate_hz: 0.1\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("min_range_m: 1.0e-09\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("max_range_m: 0.3333333333333333\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("gain: 0.7\n"), std::string::npos) << yaml;
  EXPECT_NE(yaml.find("[1.7976931348623157e+308, 2.0, 1.0e+21, 123456789.125, "
                      "0.30000000000000004, 2.2250738585072014e-308]"),
            std::string::npos)
      << yaml;
}

TEST(ConfigRoundTripTest, WritesBlockStyleNestedMaps) {
  ToyParams p;
  p.laser.waypoints = {{0.0, 0.5}, {1.0, 2.0}};
  const std::string expected =
      "rate_hz: 10.0\n"
      "min_range_m: 0.1\n"
      "max_range_m: 30.0\n"
      "laser:\n"
      "  range_noise_std_m: 0.01\n"
      "  beam_count: 181\n"
      "  enabled: true\n"
      "  seed: 42\n"
      "  mode: \"exact\"\n"
      "  gains: [1.0, 2.0]\n"
      "  waypoints:\n"
      "    - [0.0, 0.5]\n"
      "    - [1.0, 2.0]\n"
      "  inner:\n"
      "    gain: 0.5\n"
      "    offset_m: [0.0, 0.0, 0.0]\n";
  EXPECT_EQ(ToYaml(p), expected);
}

TEST(ConfigRoundTripTest, EmptySequencesAndAwkwardStringsRoundTrip) {
  const std::vector<std::string> texts = {
      "",     "true", "123",        "null",           "~",           "a: b",
      "#x",   "[1]",  "quote\"in",  "back\\slash",   "line\nbreak", "tab\tand\x01",
      " pad ", "-",   "caf\xc3\xa9", "{not: a map}", "- item"};
  for (const std::string& text : texts) {
    StringToyParams p;
    p.text = text;
    p.values.clear();
    p.pairs.clear();
    const std::string yaml = ToYaml(p);
    StringToyParams loaded;
    ASSERT_NO_THROW(loaded = LoadConfigString<StringToyParams>(yaml, "config.yaml")) << yaml;
    EXPECT_EQ(loaded.text, text) << yaml;
    EXPECT_TRUE(loaded.values.empty()) << yaml;
    EXPECT_TRUE(loaded.pairs.empty()) << yaml;
  }
}

TEST(ConfigRoundTripTest, SpecialDoublesRoundTrip) {
  StringToyParams p;
  p.values = {std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
              std::numeric_limits<double>::quiet_NaN(), -0.0};
  const std::string yaml = ToYaml(p);
  EXPECT_NE(yaml.find("values: [.inf, -.inf, .nan, -0.0]"), std::string::npos) << yaml;
  const StringToyParams loaded = LoadConfigString<StringToyParams>(yaml, "config.yaml");
  ASSERT_EQ(loaded.values.size(), 4u);
  EXPECT_TRUE(SameBits(loaded.values[0], p.values[0]));
  EXPECT_TRUE(SameBits(loaded.values[1], p.values[1]));
  EXPECT_TRUE(std::isnan(loaded.values[2]));
  EXPECT_TRUE(SameBits(loaded.values[3], -0.0));
}

}  // namespace
}  // namespace mjslam::config
