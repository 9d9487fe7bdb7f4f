#pragma once

// Reads one YAML configuration file (plus `--set key=value` overrides) into a
// plain Params struct, and writes a Params struct back as YAML. See
// config/README.md for the error format and the override syntax.

#include <string>
#include <utility>
#include <vector>

#include "common/params.h"
#include "config/archive.h"
#include "config/config_node.h"

namespace mjslam::config {

namespace internal {

/// The text of the file at `path`. Throws ConfigError ("path: cannot read
/// config file (reason)") when it is missing, a directory or unreadable.
std::string ReadTextFile(const std::string& path);

/// ParseYaml, then makes sure the top level is a map: a kNull document (empty
/// file) becomes an empty map; anything else is a problem and becomes an empty
/// map too, so that overrides and defaults still apply.
ConfigNode ParseRoot(const std::string& text, const std::string& source,
                     std::vector<ConfigProblem>* problems);

/// The top-level key that names a config's base file.
inline constexpr const char* kBaseKey = "base";

/// ParseRoot, then, when the top level has `base: PATH` (relative to the
/// directory of `source`), the base file read the same way (its own base
/// first) with this text laid over it: maps merge key by key, anything else
/// replaces, and a map whose `kind` differs from the base's replaces the
/// base's whole. Every node keeps the mark of the file that set it. A missing
/// or unreadable base, a cycle or a chain of more than 16 files is a problem.
ConfigNode ReadWithBases(const std::string& text, const std::string& source,
                         std::vector<ConfigProblem>* problems);

/// Applies each "dotted.key=value" to the map `root`, in order (a later
/// override of the same key wins). The value text is parsed as YAML; a map
/// value is merged into an existing map key by key, any other value replaces
/// the node. Inserted and replaced nodes are marked with the source
/// "--set dotted.key=value" and no line. Malformed options (no '=', empty key
/// part, YAML syntax error in the value) are appended to `problems`. Unknown
/// keys and bad values are left for the reader to report.
void ApplyOverrides(const std::vector<std::string>& overrides, ConfigNode* root,
                    std::vector<ConfigProblem>* problems);

/// Maps problems from `Validate()` (keys relative to the top struct) to the
/// mark of the text that set each key (or `source` alone for defaults).
void AddValidationProblems(const std::vector<ParamProblem>& validation,
                           const MarkTable& marks, const std::string& source,
                           std::vector<ConfigProblem>* problems);

/// Orders problems for reading: those with a line in `source` by line and
/// column, then those naming `source` alone (defaults), then the `--set`
/// ones in the order found (stable).
void SortProblems(const std::string& source, std::vector<ConfigProblem>* problems);

}  // namespace internal

/// Reads `yaml_text` (named `source_name` in messages, e.g. the file path)
/// into a T that starts from its in-class defaults: keys absent from the text
/// keep their defaults. Then applies `overrides` ("dotted.key=value", from
/// `--set` options; the value is YAML, e.g. "driver.waypoints=[[0,0],[1,2]]")
/// and runs `T::Validate()` (when T has one).
/// Throws ConfigError listing every problem at once (in text order, then
/// defaults, then `--set` options): YAML syntax errors,
/// unknown keys (with the known keys of that level), duplicate keys, wrong
/// types, out-of-range values, bad `--set` options. An empty text gives the
/// defaults (validated).
/// `marks`, when given, receives where each key was set (a file's mark, a
/// `--set` option's, or `source_name` alone for a default).
template <typename T>
T LoadConfigString(const std::string& yaml_text, const std::string& source_name,
                   const std::vector<std::string>& overrides = {},
                   internal::MarkTable* marks_out = nullptr) {
  static_assert(internal::HasSerialize<T>::value,
                "T must have template <typename Archive> void Serialize(Archive*)");
  std::vector<ConfigProblem> problems;

  // Parse the text, then lay the overrides over the tree.
  ConfigNode root = internal::ReadWithBases(yaml_text, source_name, &problems);
  internal::ApplyOverrides(overrides, &root, &problems);

  // Read the tree into a default-constructed T, recording where each key was set.
  T params{};
  internal::MarkTable marks;
  internal::ReadContext context{&problems, &marks};
  internal::ReadArchive archive(root, "", &context);
  internal::ReadFields(&archive, &params);

  // Range checks, pointed at the text that set each value.
  if constexpr (internal::HasValidate<T>::value) {
    internal::AddValidationProblems(params.Validate(), marks, source_name, &problems);
  }
  if (!problems.empty()) {
    internal::SortProblems(source_name, &problems);
    throw ConfigError(std::move(problems));
  }
  if (marks_out != nullptr) *marks_out = std::move(marks);
  return params;
}

/// LoadConfigString on the text of the file at `path` (named `path` in
/// messages). Throws ConfigError also when the file is missing or unreadable.
template <typename T>
T LoadConfigFile(const std::string& path, const std::vector<std::string>& overrides = {},
                 internal::MarkTable* marks_out = nullptr) {
  return LoadConfigString<T>(internal::ReadTextFile(path), path, overrides, marks_out);
}

/// Block-style YAML of every field of `params` (nested maps for structs),
/// doubles in shortest round-trip form: LoadConfigString<T>(ToYaml(p), ...)
/// gives back exactly `p`. Written as `config.yaml` in every run directory.
template <typename T>
std::string ToYaml(const T& params) {
  static_assert(internal::HasSerialize<T>::value,
                "T must have template <typename Archive> void Serialize(Archive*)");
  return EmitYaml(internal::WriteValue(params));
}

}  // namespace mjslam::config
