#include "config/config.h"

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

namespace mjslam::config::internal {
namespace {

using Kind = ConfigNode::Kind;

// Trims spaces and tabs at both ends.
std::string Trim(const std::string& text) {
  const std::size_t begin = text.find_first_not_of(" \t");
  if (begin == std::string::npos) return {};
  const std::size_t end = text.find_last_not_of(" \t");
  return text.substr(begin, end - begin + 1);
}

// "a.b.c" -> {"a", "b", "c"}; empty parts are kept (and rejected by the caller).
std::vector<std::string> SplitKey(const std::string& key) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  for (;;) {
    const std::size_t dot = key.find('.', start);
    parts.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) return parts;
    start = dot + 1;
  }
}

// The first entry of a map with `key`, or null.
ConfigEntry* FindEntry(ConfigNode* map, const std::string& key) {
  for (ConfigEntry& entry : map->entries) {
    if (entry.key == key) return &entry;
  }
  return nullptr;
}

// Gives every node of an override value the option's mark.
void Remark(ConfigNode* node, const SourceMark& mark) {
  node->mark = mark;
  for (ConfigNode& item : node->items) Remark(&item, mark);
  for (ConfigEntry& entry : node->entries) {
    entry.key_mark = mark;
    Remark(&entry.value, mark);
  }
}

// The scalar of a map's "kind" entry, or "" when it has none.
std::string KindOf(const ConfigNode& map) {
  for (const ConfigEntry& entry : map.entries) {
    if (entry.key == kKindKey && entry.value.kind == Kind::kScalar) return entry.value.scalar;
  }
  return {};
}

// Maps merge key by key; anything else replaces, and so does a map of
// another "kind".
void Merge(ConfigNode* target, const ConfigNode& value) {
  if (target->kind != Kind::kMap || value.kind != Kind::kMap ||
      (!KindOf(value).empty() && KindOf(value) != KindOf(*target))) {
    *target = value;
    return;
  }
  for (const ConfigEntry& entry : value.entries) {
    if (ConfigEntry* existing = FindEntry(target, entry.key)) {
      Merge(&existing->value, entry.value);
    } else {
      target->entries.push_back(entry);
    }
  }
}

}  // namespace

std::string ReadTextFile(const std::string& path) {
  const auto fail = [&path](const std::string& reason) {
    throw ConfigError({ConfigProblem{SourceMark{path, 0, 0}, "",
                                     "cannot read config file (" + reason + ")"}});
  };

  // fopen succeeds on a directory; reading it would fail with a vaguer reason.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail("is a directory");

  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  const std::unique_ptr<std::FILE, Closer> file(std::fopen(path.c_str(), "rb"));
  if (!file) fail(std::strerror(errno));
  std::string text;
  char buffer[65536];
  for (;;) {
    const std::size_t n = std::fread(buffer, 1, sizeof(buffer), file.get());
    text.append(buffer, n);
    if (n < sizeof(buffer)) break;
  }
  if (std::ferror(file.get())) fail(std::strerror(errno));
  return text;
}

ConfigNode ParseRoot(const std::string& text, const std::string& source,
                     std::vector<ConfigProblem>* problems) {
  ConfigNode root = ParseYaml(text, source, problems);
  if (root.kind == Kind::kMap) return root;
  if (root.kind != Kind::kNull) {
    problems->push_back({root.mark, "",
                         "expected a map of keys at the top level (got " + NodeText(root) + ")"});
  }
  return MapNode(root.mark);
}

namespace {

// Adds to `target` every entry of `base` it lacks, through nested maps. A map
// whose "kind" differs from the base's is a different choice: the base's
// entries of the other kind are not mixed in.
void Underlay(ConfigNode* target, const ConfigNode& base) {
  if (target->kind != Kind::kMap || base.kind != Kind::kMap) return;
  if (KindOf(*target) != KindOf(base) && !KindOf(*target).empty()) return;
  for (const ConfigEntry& entry : base.entries) {
    if (ConfigEntry* existing = FindEntry(target, entry.key)) {
      Underlay(&existing->value, entry.value);
    } else {
      target->entries.push_back(entry);
    }
  }
}

// Reads `source`'s text, then its base chain; `chain` holds the files being
// read (to refuse a cycle).
ConfigNode ReadChain(const std::string& text, const std::string& source,
                     std::vector<std::string>* chain, std::vector<ConfigProblem>* problems) {
  constexpr std::size_t kMaxDepth = 16;
  ConfigNode root = ParseRoot(text, source, problems);
  const auto base_entry = std::find_if(root.entries.begin(), root.entries.end(),
                                       [](const ConfigEntry& e) { return e.key == kBaseKey; });
  if (base_entry == root.entries.end()) return root;
  const ConfigEntry entry = *base_entry;
  root.entries.erase(base_entry);
  if (FindEntry(&root, kBaseKey) != nullptr) {
    problems->push_back({entry.key_mark, kBaseKey, "duplicate key"});
  }
  if (entry.value.kind != Kind::kScalar || entry.value.scalar.empty()) {
    problems->push_back({entry.value.mark, kBaseKey,
                         "expected the path of a config file (got " + NodeText(entry.value) + ")"});
    return root;
  }
  namespace fs = std::filesystem;
  fs::path path(entry.value.scalar);
  if (path.is_relative()) path = fs::path(source).parent_path() / path;
  const std::string name = path.lexically_normal().string();
  std::error_code ec;
  const fs::path canonical = fs::weakly_canonical(path, ec);
  const std::string key = ec ? name : canonical.string();
  if (std::find(chain->begin(), chain->end(), key) != chain->end()) {
    problems->push_back({entry.value.mark, kBaseKey,
                         "'" + name + "' is this file or one of its bases (a cycle)"});
    return root;
  }
  if (chain->size() >= kMaxDepth) {
    problems->push_back({entry.value.mark, kBaseKey,
                         "more than " + std::to_string(kMaxDepth) + " bases in a chain"});
    return root;
  }
  std::string base_text;
  try {
    base_text = ReadTextFile(name);
  } catch (const ConfigError& error) {
    problems->push_back({entry.value.mark, kBaseKey, error.problems().front().message + ": '" +
                                                         name + "'"});
    return root;
  }
  chain->push_back(key);
  const ConfigNode base = ReadChain(base_text, name, chain, problems);
  chain->pop_back();
  Underlay(&root, base);
  return root;
}

}  // namespace

ConfigNode ReadWithBases(const std::string& text, const std::string& source,
                         std::vector<ConfigProblem>* problems) {
  std::vector<std::string> chain;
  std::error_code ec;
  const std::filesystem::path canonical = std::filesystem::weakly_canonical(source, ec);
  chain.push_back(ec ? source : canonical.string());
  return ReadChain(text, source, &chain, problems);
}

void ApplyOverrides(const std::vector<std::string>& overrides, ConfigNode* root,
                    std::vector<ConfigProblem>* problems) {
  for (const std::string& option : overrides) {
    const SourceMark mark{"--set " + option, 0, 0};

    // "dotted.key=value": split at the first '='.
    const std::size_t equals = option.find('=');
    if (equals == std::string::npos) {
      problems->push_back({mark, "", "expected --set dotted.key=value"});
      continue;
    }
    const std::string key = Trim(option.substr(0, equals));
    const std::vector<std::string> parts = SplitKey(key);
    bool parts_ok = true;
    for (const std::string& part : parts) parts_ok = parts_ok && !part.empty();
    if (!parts_ok) {
      problems->push_back({mark, key, "expected a dotted key like laser.range_noise_std_m"});
      continue;
    }

    // The value is YAML: a scalar, or a flow sequence or map.
    std::vector<ConfigProblem> value_problems;
    ConfigNode value = ParseYaml(option.substr(equals + 1), mark.source, &value_problems);
    if (!value_problems.empty()) {
      for (const ConfigProblem& problem : value_problems) {
        std::string message = problem.message;
        const std::string syntax = "YAML syntax error: ";
        if (message.compare(0, syntax.size(), syntax) == 0) message.erase(0, syntax.size());
        problems->push_back({mark, key, "invalid YAML value: " + message});
      }
      continue;
    }
    Remark(&value, mark);

    // Walk (or create) the maps down to the last key part, then merge there.
    ConfigNode* node = root;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      ConfigEntry* entry = FindEntry(node, parts[i]);
      if (entry == nullptr) {
        node->entries.push_back(ConfigEntry{parts[i], mark, MapNode(mark)});
        entry = &node->entries.back();
      } else if (entry->value.kind != Kind::kMap) {
        entry->value = MapNode(mark);
      }
      node = &entry->value;
    }
    // A new kind for a choice (`--set a.kind=two`) replaces its map, as
    // `--set a={kind: two}` does: the keys of the old kind would not apply.
    if (parts.size() > 1 && parts.back() == kKindKey && value.kind == Kind::kScalar &&
        !KindOf(*node).empty() && KindOf(*node) != value.scalar) {
      node->entries.clear();
    }
    if (ConfigEntry* entry = FindEntry(node, parts.back())) {
      Merge(&entry->value, value);
    } else {
      node->entries.push_back(ConfigEntry{parts.back(), mark, std::move(value)});
    }
  }
}

void SortProblems(const std::string& source, std::vector<ConfigProblem>* problems) {
  // Text order first, then defaults, then options (in option order).
  const auto rank = [&source](const ConfigProblem& problem) {
    if (problem.mark.source == source && problem.mark.line > 0) return 0;
    if (problem.mark.source == source) return 1;
    return 2;
  };
  std::stable_sort(problems->begin(), problems->end(),
                   [&rank](const ConfigProblem& a, const ConfigProblem& b) {
                     const int rank_a = rank(a);
                     const int rank_b = rank(b);
                     if (rank_a != rank_b) return rank_a < rank_b;
                     if (rank_a != 0) return false;
                     if (a.mark.line != b.mark.line) return a.mark.line < b.mark.line;
                     return a.mark.column < b.mark.column;
                   });
}

void AddValidationProblems(const std::vector<ParamProblem>& validation,
                           const MarkTable& marks, const std::string& source,
                           std::vector<ConfigProblem>* problems) {
  for (const ParamProblem& problem : validation) {
    problems->push_back({marks.Find(problem.key, source), problem.key,
                         "expected " + problem.expected + " (got " + problem.value + ")"});
  }
}

}  // namespace mjslam::config::internal
