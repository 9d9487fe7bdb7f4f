#pragma once

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace mjslam {

/// A field of a `*Params` struct, as visited by `Serialize(Archive*)`. The
/// archive (YAML reader, writer, `--set` overrides; see config/) reads or
/// writes `*value` under the key `name`.
template <typename T>
struct NameValue {
  const char* name;
  T* value;
};

/// `a->Visit(MJSLAM_NVP(rate_hz));` inside a Params' `Serialize`.
#define MJSLAM_NVP(field) ::mjslam::NameValue<decltype(field)>{#field, &(field)}

/// Whether `Archive` writes a Params struct out (config's WriteArchive says
/// so with `static constexpr bool kWrites = true`) rather than reading or
/// listing its fields: a Serialize may leave out a field at its default
/// when writing, so that an optional key absent from a file stays absent
/// from the resolved config.
template <typename Archive, typename = void>
struct ArchiveWrites : std::false_type {};
template <typename Archive>
struct ArchiveWrites<Archive, std::void_t<decltype(Archive::kWrites)>>
    : std::bool_constant<Archive::kWrites> {};

/// A key that a Params struct no longer reads, and the key (relative to the
/// same struct) that took its place. A Params lists its own in
/// `static constexpr RetiredKey kRetiredKeys[]`; the config reader reports
/// such a key where it is given, with the new one, instead of "unknown key".
struct RetiredKey {
  /// The old key.
  const char* key;
  /// The key that replaced it.
  const char* replacement;
  /// How the value moves beyond the new key's name, or "".
  const char* note;
};

/// One thing wrong with a parameter value: the dotted key (relative to the
/// struct that validated it), the value as text, and what was expected.
struct ParamProblem {
  std::string key;
  std::string value;
  std::string expected;
};

/// Shortest round-trip text of a value, for error messages.
template <typename T>
std::string ValueText(const T& value) {
  if constexpr (std::is_same_v<T, bool>) {
    return value ? "true" : "false";
  } else if constexpr (std::is_arithmetic_v<T>) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
  } else {
    return std::string(value);
  }
}

/// Collects the problems of a Params struct so that all are reported at once.
/// Each Params has `std::vector<ParamProblem> Validate() const` built with it.
class ParamChecker {
 public:
  /// Records a problem with `key` unless `ok`.
  template <typename T>
  void Require(bool ok, std::string_view key, const T& value,
               std::string_view expected) {
    if (!ok) problems_.push_back({std::string(key), ValueText(value), std::string(expected)});
  }
  /// value > 0 (and finite: YAML's `.inf` is no size, rate or time).
  template <typename T>
  void Positive(std::string_view key, T value) {
    Require(value > 0 && IsFinite(value), key, value,
            IsFinite(value) ? "a value > 0" : "a finite value > 0");
  }
  /// value >= 0 (and finite).
  template <typename T>
  void NonNegative(std::string_view key, T value) {
    Require(value >= 0 && IsFinite(value), key, value,
            IsFinite(value) ? "a value >= 0" : "a finite value >= 0");
  }
  /// lo <= value <= hi.
  template <typename T>
  void InRange(std::string_view key, T value, T lo, T hi) {
    Require(value >= lo && value <= hi, key, value,
            "a value in [" + ValueText(lo) + ", " + ValueText(hi) + "]");
  }
  /// One of `choices`.
  void OneOf(std::string_view key, const std::string& value,
             const std::vector<std::string>& choices);
  /// Adds the problems of a nested struct, prefixing their keys with `prefix.`.
  void Merge(std::string_view prefix, const std::vector<ParamProblem>& nested);

  const std::vector<ParamProblem>& problems() const { return problems_; }

 private:
  template <typename T>
  static bool IsFinite(T value) {
    if constexpr (std::is_floating_point_v<T>) {
      return std::isfinite(value);
    } else {
      return true;
    }
  }

  std::vector<ParamProblem> problems_;
};

/// Bad configuration. `what()` lists every problem, one per line.
class ParamError : public std::runtime_error {
 public:
  explicit ParamError(const std::string& message) : std::runtime_error(message) {}
};

/// Throws ParamError listing `problems` as "key: expected ... (got value)",
/// each line prefixed with `context` when it is not empty.
void ThrowIfProblems(const std::vector<ParamProblem>& problems,
                     std::string_view context = {});

}  // namespace mjslam
