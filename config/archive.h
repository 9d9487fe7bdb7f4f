#pragma once

// Archives that visit a Params struct's `Serialize(Archive*)` over a ConfigNode
// tree: ReadArchive fills the struct (collecting problems), WriteArchive builds
// the tree of every field. Header-only templates, free of yaml-cpp; the
// non-template parts live in config/archive.cc. Users call config/config.h.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "common/params.h"
#include "config/config_node.h"

namespace mjslam::config::internal {

class ReadArchive;

/// True when T has `template <typename Archive> void Serialize(Archive*)`.
template <typename T, typename = void>
struct HasSerialize : std::false_type {};
template <typename T>
struct HasSerialize<T, std::void_t<decltype(std::declval<T&>().Serialize(
                           std::declval<ReadArchive*>()))>> : std::true_type {};

/// True when T has `std::vector<ParamProblem> Validate() const`.
template <typename T, typename = void>
struct HasValidate : std::false_type {};
template <typename T>
struct HasValidate<T, std::void_t<decltype(std::declval<const T&>().Validate())>>
    : std::true_type {};

template <typename T>
struct IsVector : std::false_type {};
template <typename U, typename A>
struct IsVector<std::vector<U, A>> : std::true_type {};

template <typename T>
struct IsArray : std::false_type {};
template <typename U, std::size_t N>
struct IsArray<std::array<U, N>> : std::true_type {};

/// Whether T lists keys it no longer reads (`static constexpr RetiredKey
/// kRetiredKeys[]`).
template <typename T, typename = void>
struct HasRetiredKeys : std::false_type {};
template <typename T>
struct HasRetiredKeys<T, std::void_t<decltype(T::kRetiredKeys)>> : std::true_type {};

/// A tagged choice: a `std::variant` of Params structs, each with
/// `static constexpr const char* kKind`, the name its YAML map gives under
/// `kind:` (Drake's variant by tag).
template <typename T>
struct IsVariant : std::false_type {};
template <typename... A>
struct IsVariant<std::variant<A...>> : std::true_type {};

/// The key whose value picks a tagged choice's alternative.
inline constexpr const char* kKindKey = "kind";

/// Scalar field types read and written by ReadLeaf / WriteLeaf.
template <typename T>
inline constexpr bool kIsLeaf =
    std::is_same_v<T, double> || std::is_same_v<T, int> || std::is_same_v<T, bool> ||
    std::is_same_v<T, std::uint64_t> || std::is_same_v<T, std::string>;

/// The mark of every value read, by dotted key ("laser.rate_hz",
/// "driver.waypoints[1][0]"), so that problems from `Validate()` can point at
/// the text that set the value.
class MarkTable {
 public:
  /// Records where `key` was set; `is_struct` for nested Params maps.
  void Record(const std::string& key, const SourceMark& mark, bool is_struct);

  /// The mark recorded for `key`; else for its longest recorded prefix that is
  /// a field or element (not a struct: "a.b[2]" -> "a.b", "a.b.extra" ->
  /// "a.b"); else `source` alone (the value came from defaults).
  SourceMark Find(const std::string& key, const std::string& source) const;

 private:
  struct Recorded {
    SourceMark mark;
    bool is_struct = false;
  };
  std::map<std::string, Recorded> marks_;
};

/// State shared by the archives of one read.
struct ReadContext {
  std::vector<ConfigProblem>* problems = nullptr;
  MarkTable* marks = nullptr;

  void Problem(const SourceMark& mark, const std::string& key, std::string message) {
    problems->push_back({mark, key, std::move(message)});
  }
};

/// Text of a node for "(got ...)": the scalar, quoted when it was quoted;
/// "null"; "a map"; "a sequence of N items".
std::string NodeText(const ConfigNode& node);

/// Converts a scalar node to a leaf value. On failure returns false and sets
/// `expected` (e.g. "a number", "an integer in [-2147483648, 2147483647]").
/// Numbers: decimal, optional sign; doubles also `.inf`, `-.inf`, `.nan`.
/// Bools: true/false (also True/TRUE/False/FALSE). Quoted scalars are strings
/// only. Strings accept any scalar, not null.
bool ReadLeaf(const ConfigNode& node, double* value, std::string* expected);
bool ReadLeaf(const ConfigNode& node, int* value, std::string* expected);
bool ReadLeaf(const ConfigNode& node, bool* value, std::string* expected);
bool ReadLeaf(const ConfigNode& node, std::uint64_t* value, std::string* expected);
bool ReadLeaf(const ConfigNode& node, std::string* value, std::string* expected);

/// Shortest text that reads back to the same value. Doubles always carry a
/// '.' ("3.0", "1.0e-09", ".inf", ".nan") so YAML 1.1 readers see floats.
ConfigNode WriteLeaf(double value);
ConfigNode WriteLeaf(int value);
ConfigNode WriteLeaf(bool value);
ConfigNode WriteLeaf(std::uint64_t value);
ConfigNode WriteLeaf(const std::string& value);

/// "a.b" from "a" and "b"; "b" when `prefix` is empty.
inline std::string JoinKey(const std::string& prefix, const char* name) {
  return prefix.empty() ? std::string(name) : prefix + "." + name;
}

/// What a field of type T must look like, for "expected ..." messages.
template <typename T>
std::string Describe(bool plural) {
  if constexpr (HasSerialize<T>::value) {
    return plural ? "maps of keys" : "a map of keys";
  } else if constexpr (IsVariant<T>::value) {
    return plural ? "maps with a kind" : "a map with a kind";
  } else if constexpr (IsVector<T>::value) {
    return std::string(plural ? "sequences of " : "a sequence of ") +
           Describe<typename T::value_type>(true);
  } else if constexpr (IsArray<T>::value) {
    return std::string(plural ? "sequences of " : "a sequence of ") +
           std::to_string(std::tuple_size_v<T>) + " " +
           Describe<typename T::value_type>(true);
  } else if constexpr (std::is_same_v<T, double>) {
    return plural ? "numbers" : "a number";
  } else if constexpr (std::is_same_v<T, int>) {
    return plural ? "integers" : "an integer";
  } else if constexpr (std::is_same_v<T, std::uint64_t>) {
    return plural ? "non-negative integers" : "a non-negative integer";
  } else if constexpr (std::is_same_v<T, bool>) {
    return plural ? "booleans" : "true or false";
  } else {
    return plural ? "strings" : "a string";
  }
}

/// Reads `node` into `*value` (key `key`). On a problem, records it and
/// leaves `*value` as it was; returns whether the read succeeded.
template <typename T>
bool ReadValue(const ConfigNode& node, const std::string& key, T* value,
               ReadContext* context);

template <typename T>
ConfigNode WriteValue(const T& value);

/// Visits the fields of a Params struct while reading one map node.
class ReadArchive {
 public:
  /// `map` must be a kMap node; `prefix` is its dotted key ("" at the top).
  ReadArchive(const ConfigNode& map, std::string prefix, ReadContext* context)
      : map_(map), prefix_(std::move(prefix)), context_(context) {}

  /// Reads field `field.name` if the map has it (first occurrence); absent
  /// keys keep their current (default) value.
  template <typename T>
  void Visit(const NameValue<T>& field) {
    known_.emplace_back(field.name);
    for (const ConfigEntry& entry : map_.entries) {
      if (entry.key == field.name) {
        ReadValue(entry.value, JoinKey(prefix_, field.name), field.value, context_);
        return;
      }
    }
  }

  /// Names a key the struct no longer reads: Finish reports it with its
  /// replacement instead of as unknown.
  void Retire(const RetiredKey& retired) { retired_.push_back(retired); }

  /// After Serialize: reports duplicate keys, retired keys (with the key
  /// that replaced each) and keys no field visited (listing the known keys
  /// of this level).
  void Finish();

 private:
  const ConfigNode& map_;
  std::string prefix_;
  ReadContext* context_;
  std::vector<std::string> known_;
  std::vector<RetiredKey> retired_;
};

/// Reads the fields of the Params `*params` from `archive`'s map, then
/// reports that map's retired, duplicate and unknown keys.
template <typename T>
void ReadFields(ReadArchive* archive, T* params) {
  params->Serialize(archive);
  if constexpr (HasRetiredKeys<T>::value) {
    for (const RetiredKey& retired : T::kRetiredKeys) archive->Retire(retired);
  }
  archive->Finish();
}

/// The alternative of variant `V` at `index`, default-constructed.
template <typename V, std::size_t... I>
V AlternativeAt(std::size_t index, std::index_sequence<I...>) {
  V result;
  ((I == index ? (void)result.template emplace<I>() : (void)0), ...);
  return result;
}

/// Rewords the problems from `first` on that are unknown keys under the
/// choice `key` and that the tree of another alternative (`trees[j]`, kind
/// `kinds[j]`) has: "a key of kind 'command', not of kind 'odometry'".
/// `kind_given`: whether the map names its kind (else the kind is the one
/// already there: the default's or a base's).
void NameKeysOfOtherKinds(const std::string& key, const std::vector<std::string>& kinds,
                          std::size_t chosen, bool kind_given,
                          const std::vector<ConfigNode>& trees, std::size_t first,
                          ReadContext* context);

/// Reads the map `node` of a tagged choice: its `kind` picks the alternative
/// (absent: the current one stays), which is then read from the map's other
/// keys; a key only another kind has is a problem naming both kinds.
template <typename... A>
bool ReadChoice(const ConfigNode& node, const std::string& key, std::variant<A...>* value,
                ReadContext* context) {
  using Kind = ConfigNode::Kind;
  const std::vector<std::string> kinds = {A::kKind...};

  // The kind: the map's first `kind` entry, else the current alternative's.
  std::size_t index = value->index();
  bool kind_given = false;
  for (const ConfigEntry& entry : node.entries) {
    if (entry.key != kKindKey) continue;
    const auto named = entry.value.kind == Kind::kScalar
                           ? std::find(kinds.begin(), kinds.end(), entry.value.scalar)
                           : kinds.end();
    if (named == kinds.end()) {
      std::string names;
      for (std::size_t k = 0; k < kinds.size(); ++k) {
        names += (k == 0 ? "" : k + 1 == kinds.size() ? " or " : ", ") + kinds[k];
      }
      context->Problem(entry.value.mark, JoinKey(key, kKindKey),
                       "expected " + names + " (got " + NodeText(entry.value) + ")");
      return false;
    }
    index = static_cast<std::size_t>(named - kinds.begin());
    kind_given = true;
    break;
  }
  if (index != value->index()) {
    *value = AlternativeAt<std::variant<A...>>(index, std::index_sequence_for<A...>{});
  }

  // The alternative's keys, `kind` among them.
  const std::size_t problems_before = context->problems->size();
  std::visit(
      [&](auto& alternative) {
        ReadArchive archive(node, key, context);
        std::string kind = kinds[index];
        archive.Visit(NameValue<std::string>{kKindKey, &kind});
        ReadFields(&archive, &alternative);
      },
      *value);
  if (context->problems->size() == problems_before) return true;
  const std::vector<ConfigNode> trees = {WriteValue(A{})...};
  NameKeysOfOtherKinds(key, kinds, index, kind_given, trees, problems_before, context);
  return false;
}

template <typename T>
bool ReadValue(const ConfigNode& node, const std::string& key, T* value,
               ReadContext* context) {
  using Kind = ConfigNode::Kind;
  context->marks->Record(key, node.mark, HasSerialize<T>::value || IsVariant<T>::value);
  if constexpr (HasSerialize<T>::value) {
    // Nested Params: a map (null, e.g. `laser:` alone, keeps every default).
    if (node.kind == Kind::kNull) return true;
    if (node.kind != Kind::kMap) {
      context->Problem(node.mark, key,
                       "expected " + Describe<T>(false) + " (got " + NodeText(node) + ")");
      return false;
    }
    const std::size_t problems_before = context->problems->size();
    ReadArchive archive(node, key, context);
    ReadFields(&archive, value);
    return context->problems->size() == problems_before;
  } else if constexpr (IsVariant<T>::value) {
    // A tagged choice: a map (null keeps the current alternative as it is).
    if (node.kind == Kind::kNull) return true;
    if (node.kind != Kind::kMap) {
      context->Problem(node.mark, key,
                       "expected " + Describe<T>(false) + " (got " + NodeText(node) + ")");
      return false;
    }
    return ReadChoice(node, key, value, context);
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    // Sequences: read every item into a copy, assign only when all are good.
    bool length_ok = node.kind == Kind::kSequence;
    if constexpr (IsArray<T>::value) {
      length_ok = length_ok && node.items.size() == std::tuple_size_v<T>;
    }
    if (!length_ok) {
      context->Problem(node.mark, key,
                       "expected " + Describe<T>(false) + " (got " + NodeText(node) + ")");
      return false;
    }
    T parsed{};
    if constexpr (IsVector<T>::value) parsed.resize(node.items.size());
    bool ok = true;
    for (std::size_t i = 0; i < node.items.size(); ++i) {
      ok = ReadValue(node.items[i], key + "[" + std::to_string(i) + "]", &parsed[i],
                     context) &&
           ok;
    }
    if (ok) *value = std::move(parsed);
    return ok;
  } else {
    static_assert(kIsLeaf<T>,
                  "unsupported Params field type: use double, int, bool, std::uint64_t, "
                  "std::string, std::vector/std::array of those, or a struct with "
                  "Serialize");
    T parsed{};
    std::string expected;
    if (!ReadLeaf(node, &parsed, &expected)) {
      context->Problem(node.mark, key,
                       "expected " + expected + " (got " + NodeText(node) + ")");
      return false;
    }
    *value = std::move(parsed);
    return true;
  }
}

/// Visits the fields of a Params struct while building one map node.
class WriteArchive {
 public:
  /// ArchiveWrites (common/params.h): this archive writes.
  static constexpr bool kWrites = true;
  /// `map` must be a kMap node; fields are appended in visiting order.
  explicit WriteArchive(ConfigNode* map) : map_(map) {}

  template <typename T>
  void Visit(const NameValue<T>& field) {
    map_->entries.push_back(ConfigEntry{field.name, SourceMark{}, WriteValue(*field.value)});
  }

 private:
  ConfigNode* map_;
};

/// The tree of `value`: a map for Params structs (for a tagged choice, its
/// `kind` first, then the alternative's fields), sequences for vectors and
/// arrays, scalars for leaves.
template <typename T>
ConfigNode WriteValue(const T& value) {
  if constexpr (HasSerialize<T>::value) {
    // Serialize is not const (it hands out field pointers): visit a copy.
    T copy = value;
    ConfigNode node = MapNode();
    WriteArchive archive(&node);
    copy.Serialize(&archive);
    return node;
  } else if constexpr (IsVariant<T>::value) {
    return std::visit(
        [](const auto& alternative) {
          ConfigNode node = WriteValue(alternative);
          const std::string kind = std::decay_t<decltype(alternative)>::kKind;
          node.entries.insert(node.entries.begin(),
                              ConfigEntry{kKindKey, SourceMark{}, WriteLeaf(kind)});
          return node;
        },
        value);
  } else if constexpr (IsVector<T>::value || IsArray<T>::value) {
    ConfigNode node = SequenceNode();
    for (const auto& item : value) node.items.push_back(WriteValue(item));
    return node;
  } else {
    static_assert(kIsLeaf<T>, "unsupported Params field type");
    return WriteLeaf(value);
  }
}

}  // namespace mjslam::config::internal
