#include "config/archive.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <string_view>
#include <system_error>

namespace mjslam::config::internal {
namespace {

using Kind = ConfigNode::Kind;

// Longest text shown for a value in "(got ...)".
constexpr std::size_t kMaxValueText = 60;

// Drops one leading '+' (YAML allows it, std::from_chars does not).
std::string_view WithoutPlus(std::string_view text) {
  if (text.size() > 1 && text[0] == '+' && text[1] != '-' && text[1] != '+') {
    text.remove_prefix(1);
  }
  return text;
}

// from_chars over the whole text, or nothing.
template <typename T>
std::errc ParseWhole(std::string_view text, T* value) {
  if (text.empty()) return std::errc::invalid_argument;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), *value);
  if (result.ec != std::errc()) return result.ec;
  if (result.ptr != text.data() + text.size()) return std::errc::invalid_argument;
  return std::errc();
}

// YAML 1.2 core-schema floats: [-+]digits[.digits][e[-+]digits], .inf, .nan.
std::errc ParseDouble(const std::string& text, double* value) {
  if (text == ".inf" || text == ".Inf" || text == ".INF" || text == "+.inf" ||
      text == "+.Inf" || text == "+.INF") {
    *value = std::numeric_limits<double>::infinity();
    return std::errc();
  }
  if (text == "-.inf" || text == "-.Inf" || text == "-.INF") {
    *value = -std::numeric_limits<double>::infinity();
    return std::errc();
  }
  if (text == ".nan" || text == ".NaN" || text == ".NAN") {
    *value = std::numeric_limits<double>::quiet_NaN();
    return std::errc();
  }
  // Only digits, sign, '.', exponent: rejects from_chars' "inf", "nan", "0x1p3".
  const std::string_view body = WithoutPlus(text);
  if (body.find_first_not_of("0123456789+-.eE") != std::string_view::npos) {
    return std::errc::invalid_argument;
  }
  return ParseWhole(body, value);
}

bool IsPlainScalar(const ConfigNode& node) {
  return node.kind == Kind::kScalar && !node.quoted;
}

// Edit distance counting a swap of neighbours as one edit (optimal string
// alignment), for "did you mean" suggestions: "rnage" -> "range" is 1.
std::size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::vector<std::size_t>> d(a.size() + 1, std::vector<std::size_t>(b.size() + 1));
  for (std::size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (std::size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    for (std::size_t j = 1; j <= b.size(); ++j) {
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1,
                          d[i - 1][j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

// Whether the dotted `path` ("noise.v_std_mps") names an entry of `tree`'s
// nested maps.
bool HasKeyPath(const ConfigNode& tree, const std::string& path) {
  const ConfigNode* node = &tree;
  std::size_t start = 0;
  for (;;) {
    const std::size_t dot = path.find('.', start);
    const std::string part = path.substr(start, dot == std::string::npos ? dot : dot - start);
    const auto entry = std::find_if(node->entries.begin(), node->entries.end(),
                                    [&part](const ConfigEntry& e) { return e.key == part; });
    if (entry == node->entries.end()) return false;
    if (dot == std::string::npos) return true;
    node = &entry->value;
    start = dot + 1;
  }
}

}  // namespace

void NameKeysOfOtherKinds(const std::string& key, const std::vector<std::string>& kinds,
                          std::size_t chosen, bool kind_given,
                          const std::vector<ConfigNode>& trees, std::size_t first,
                          ReadContext* context) {
  const std::string prefix = key + ".";
  const std::string unknown = "unknown key";
  for (std::size_t i = first; i < context->problems->size(); ++i) {
    ConfigProblem& problem = (*context->problems)[i];
    if (problem.key.compare(0, prefix.size(), prefix) != 0 ||
        problem.message.compare(0, unknown.size(), unknown) != 0) {
      continue;
    }
    const std::string path = problem.key.substr(prefix.size());
    for (std::size_t j = 0; j < kinds.size(); ++j) {
      if (j == chosen || !HasKeyPath(trees[j], path)) continue;
      // Keep the list of the keys known here, drop a "did you mean".
      const std::size_t list = problem.message.find(" (");
      problem.message = "a key of kind '" + kinds[j] + "', not of kind '" + kinds[chosen] + "'" +
                        (kind_given ? "" : " (no kind given here: the base's or the default)") +
                        (list == std::string::npos ? "" : problem.message.substr(list));
      break;
    }
  }
}

void MarkTable::Record(const std::string& key, const SourceMark& mark, bool is_struct) {
  marks_[key] = Recorded{mark, is_struct};
}

SourceMark MarkTable::Find(const std::string& key, const std::string& source) const {
  // The key itself (a field, an element, or a nested struct).
  if (const auto it = marks_.find(key); it != marks_.end()) return it->second.mark;

  // Else the closest enclosing field or element: "a.b[2][0]" -> "a.b[2]" -> "a.b".
  std::string prefix = key;
  for (;;) {
    const std::size_t cut = prefix.find_last_of(".[");
    if (cut == std::string::npos || cut == 0) break;
    prefix.resize(cut);
    const auto it = marks_.find(prefix);
    if (it != marks_.end()) {
      if (it->second.is_struct) break;
      return it->second.mark;
    }
  }

  // Not in the text: the value is a default.
  return SourceMark{source, 0, 0};
}

std::string NodeText(const ConfigNode& node) {
  switch (node.kind) {
    case Kind::kNull:
      return "null";
    case Kind::kMap:
      return "a map";
    case Kind::kSequence:
      return "a sequence of " + std::to_string(node.items.size()) +
             (node.items.size() == 1 ? " item" : " items");
    case Kind::kScalar:
      break;
  }
  std::string text = node.scalar;
  if (text.size() > kMaxValueText) text = text.substr(0, kMaxValueText - 3) + "...";
  return node.quoted ? "\"" + text + "\"" : text;
}

bool ReadLeaf(const ConfigNode& node, double* value, std::string* expected) {
  *expected = node.quoted ? "an unquoted number" : "a number";
  if (!IsPlainScalar(node)) return false;
  const std::errc ec = ParseDouble(node.scalar, value);
  if (ec == std::errc::result_out_of_range) *expected = "a number within the range of a double";
  return ec == std::errc();
}

bool ReadLeaf(const ConfigNode& node, int* value, std::string* expected) {
  *expected = node.quoted ? "an unquoted integer" : "an integer";
  if (!IsPlainScalar(node)) return false;
  const std::errc ec = ParseWhole(WithoutPlus(node.scalar), value);
  if (ec == std::errc::result_out_of_range) {
    *expected = "an integer in [" + std::to_string(std::numeric_limits<int>::min()) + ", " +
                std::to_string(std::numeric_limits<int>::max()) + "]";
  }
  return ec == std::errc();
}

bool ReadLeaf(const ConfigNode& node, std::uint64_t* value, std::string* expected) {
  *expected = node.quoted ? "an unquoted non-negative integer" : "a non-negative integer";
  if (!IsPlainScalar(node)) return false;
  const std::errc ec = ParseWhole(WithoutPlus(node.scalar), value);
  if (ec == std::errc::result_out_of_range) {
    *expected = "a non-negative integer <= " +
                std::to_string(std::numeric_limits<std::uint64_t>::max());
  }
  return ec == std::errc();
}

bool ReadLeaf(const ConfigNode& node, bool* value, std::string* expected) {
  *expected = node.quoted ? "unquoted true or false" : "true or false";
  if (!IsPlainScalar(node)) return false;
  const std::string& text = node.scalar;
  if (text == "true" || text == "True" || text == "TRUE") {
    *value = true;
    return true;
  }
  if (text == "false" || text == "False" || text == "FALSE") {
    *value = false;
    return true;
  }
  return false;
}

bool ReadLeaf(const ConfigNode& node, std::string* value, std::string* expected) {
  *expected = "a string";
  if (node.kind != Kind::kScalar) return false;
  *value = node.scalar;
  return true;
}

ConfigNode WriteLeaf(double value) {
  if (std::isnan(value)) return ScalarNode(".nan", false);
  if (std::isinf(value)) return ScalarNode(value > 0 ? ".inf" : "-.inf", false);

  // Shortest text that reads back to the same double.
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  std::string text(buffer, result.ptr);

  // Keep a '.' in the mantissa so every YAML reader sees a float: "3" -> "3.0",
  // "1e-09" -> "1.0e-09".
  if (text.find('.') == std::string::npos) {
    const std::size_t exponent = text.find('e');
    if (exponent == std::string::npos) {
      text += ".0";
    } else {
      text.insert(exponent, ".0");
    }
  }
  return ScalarNode(std::move(text), false);
}

ConfigNode WriteLeaf(int value) { return ScalarNode(std::to_string(value), false); }

ConfigNode WriteLeaf(bool value) { return ScalarNode(value ? "true" : "false", false); }

ConfigNode WriteLeaf(std::uint64_t value) { return ScalarNode(std::to_string(value), false); }

ConfigNode WriteLeaf(const std::string& value) { return ScalarNode(value, true); }

void ReadArchive::Finish() {
  const std::vector<ConfigEntry>& entries = map_.entries;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const ConfigEntry& entry = entries[i];
    const std::string key = JoinKey(prefix_, entry.key.c_str());

    // A key seen before at this level.
    const auto first = std::find_if(entries.begin(), entries.begin() + static_cast<std::ptrdiff_t>(i),
                                    [&](const ConfigEntry& e) { return e.key == entry.key; });
    if (first != entries.begin() + static_cast<std::ptrdiff_t>(i)) {
      context_->Problem(entry.key_mark, key,
                        "duplicate key (first given at " + FormatMark(first->key_mark) + ")");
      continue;
    }

    // A key that no field visited: list the known ones, suggest the closest.
    if (std::find(known_.begin(), known_.end(), entry.key) != known_.end()) continue;

    // A key the struct once read: name the key that replaced it.
    const auto retired = std::find_if(retired_.begin(), retired_.end(),
                                      [&](const RetiredKey& r) { return entry.key == r.key; });
    if (retired != retired_.end()) {
      const std::string note = retired->note;
      context_->Problem(entry.key_mark, key,
                        "a retired key, now " + JoinKey(prefix_, retired->replacement) +
                            (note.empty() ? "" : " (" + note + ")"));
      continue;
    }
    std::string message = "unknown key";
    std::size_t best_distance = std::numeric_limits<std::size_t>::max();
    const std::string* best = nullptr;
    for (const std::string& name : known_) {
      const std::size_t distance = EditDistance(entry.key, name);
      if (distance < best_distance) {
        best_distance = distance;
        best = &name;
      }
    }
    // Suggest only close matches: one edit per four characters, at least one.
    if (best != nullptr && best_distance <= std::max<std::size_t>(1, entry.key.size() / 4)) {
      message += ", did you mean '" + *best + "'?";
    }
    if (known_.empty()) {
      message += " (no keys are known here)";
    } else {
      message += " (known keys";
      message += prefix_.empty() ? "" : " of " + prefix_;
      message += ":";
      for (std::size_t k = 0; k < known_.size(); ++k) {
        message += (k == 0 ? " " : ", ") + known_[k];
      }
      message += ")";
    }
    context_->Problem(entry.key_mark, key, message);
  }
}

}  // namespace mjslam::config::internal
