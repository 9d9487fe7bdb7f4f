#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace mjslam::config {

/// Where a configuration value came from: a file name (or a `--set key=value`
/// option) and a 1-based line and column. `line == 0` means no position is
/// known (the value came from a `--set` option, or from defaults): only
/// `source` is printed.
struct SourceMark {
  std::string source;
  int line = 0;
  int column = 0;
};

/// "source:line:col", or "source" alone when `mark.line == 0`.
std::string FormatMark(const SourceMark& mark);

struct ConfigEntry;

/// A YAML document as plain data, free of yaml-cpp, so that the header-only
/// archives (config/archive.h) can visit Params structs over it. Every node
/// keeps the mark of the text it came from.
struct ConfigNode {
  enum class Kind { kNull, kScalar, kSequence, kMap };

  Kind kind = Kind::kNull;
  /// kScalar: the text as written (quotes removed, escapes resolved).
  std::string scalar;
  /// kScalar: quoted or tagged `!!str`, so always a string, never a number.
  bool quoted = false;
  /// kSequence: the items in order.
  std::vector<ConfigNode> items;
  /// kMap: the entries in file order; duplicate keys are kept (yaml-cpp 0.7
  /// accepts them silently), so the reader can reject them.
  std::vector<ConfigEntry> entries;
  /// Where the node starts.
  SourceMark mark;
};

/// One key of a map node.
struct ConfigEntry {
  std::string key;
  /// Where the key starts.
  SourceMark key_mark;
  ConfigNode value;
};

/// A scalar node (`quoted`: always a string).
ConfigNode ScalarNode(std::string text, bool quoted, SourceMark mark = {});
/// An empty sequence node.
ConfigNode SequenceNode(SourceMark mark = {});
/// An empty map node.
ConfigNode MapNode(SourceMark mark = {});

/// One thing wrong with a configuration.
struct ConfigProblem {
  /// Where the offending text is (or the `--set` option, or the file alone).
  SourceMark mark;
  /// Dotted key, e.g. "laser.range_noise_std_m"; empty when the problem is not
  /// about one key (YAML syntax error, unreadable file).
  std::string key;
  /// What is wrong, e.g. "expected a value >= 0 (got -1)".
  std::string message;
};

/// "file:line:col: dotted.key: message" (the mark and key parts are left out
/// when unknown or empty).
std::string FormatProblem(const ConfigProblem& problem);

/// Bad configuration: unreadable file, YAML syntax error, unknown or duplicate
/// key, wrong type, out-of-range value, bad `--set` option. `what()` lists
/// every problem found, one per line, each formatted by FormatProblem.
class ConfigError : public std::runtime_error {
 public:
  /// `problems` must not be empty.
  explicit ConfigError(std::vector<ConfigProblem> problems);

  /// The problems, in the order they were found.
  const std::vector<ConfigProblem>& problems() const { return problems_; }

 private:
  std::vector<ConfigProblem> problems_;
};

/// Parses one YAML document with yaml-cpp into a ConfigNode whose marks name
/// `source`. An empty text gives a kNull node. Syntax errors, more than one
/// document, non-scalar map keys and aliases nested too deeply (cycles) are
/// appended to `problems` (with line:col) and leave a kNull node in place.
/// Never throws for bad input.
ConfigNode ParseYaml(const std::string& text, const std::string& source,
                     std::vector<ConfigProblem>* problems);

/// Block-style YAML for `node`: maps as indented blocks, sequences of scalars
/// in flow style (`[0.1, 2.0]`), other sequences as block lists of flow
/// items, quoted scalars double-quoted with escapes, other scalars verbatim.
/// The result parses back (ParseYaml) to the same tree, marks aside.
std::string EmitYaml(const ConfigNode& node);

}  // namespace mjslam::config
