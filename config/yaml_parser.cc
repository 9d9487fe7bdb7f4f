// The only file of mjslam that includes yaml-cpp: YAML text -> ConfigNode.

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

#include "config/config_node.h"

namespace mjslam::config {
namespace {

// Aliases can build cycles (`a: &x [*x]`) or exponentially large trees that
// yaml-cpp hands over as shared nodes; the copy stops at these limits.
constexpr int kMaxDepth = 64;
constexpr std::size_t kMaxNodes = 1000000;

class Converter {
 public:
  Converter(const std::string& source, std::vector<ConfigProblem>* problems)
      : source_(source), problems_(problems) {}

  // 1-based mark; `fallback` when yaml-cpp has none.
  SourceMark Mark(const YAML::Mark& mark, const SourceMark& fallback) const {
    if (mark.is_null() || mark.line < 0) return fallback;
    return SourceMark{source_, mark.line + 1, mark.column + 1};
  }

  ConfigNode Convert(const YAML::Node& node, const SourceMark& fallback, int depth) {
    const SourceMark mark = Mark(node.Mark(), fallback);
    if (stopped_) return ConfigNode{};

    // Guard against alias cycles and alias bombs.
    ++count_;
    if (depth > kMaxDepth || count_ > kMaxNodes) {
      stopped_ = true;
      problems_->push_back({mark, "",
                            "YAML nested deeper than " + std::to_string(kMaxDepth) +
                                " levels or larger than " + std::to_string(kMaxNodes) +
                                " nodes (recursive alias?)"});
      return ConfigNode{};
    }

    switch (node.Type()) {
      case YAML::NodeType::Scalar: {
        // yaml-cpp tags quoted scalars "!", plain ones "?".
        const std::string& tag = node.Tag();
        const bool quoted = tag == "!" || tag == "tag:yaml.org,2002:str";
        return ScalarNode(node.Scalar(), quoted, mark);
      }
      case YAML::NodeType::Sequence: {
        ConfigNode out = SequenceNode(mark);
        for (const YAML::Node& item : node) out.items.push_back(Convert(item, mark, depth + 1));
        return out;
      }
      case YAML::NodeType::Map: {
        // Iterate the pairs: duplicate keys are all kept, in order.
        ConfigNode out = MapNode(mark);
        for (auto it = node.begin(); it != node.end(); ++it) {
          const YAML::Node key = it->first;  // copies: it-> is a temporary
          const YAML::Node value = it->second;
          const SourceMark key_mark = Mark(key.Mark(), mark);
          if (!key.IsScalar()) {
            problems_->push_back({key_mark, "", "expected a plain key (got a null, map or sequence key)"});
            continue;
          }
          // An empty value (`key:`) is marked by yaml-cpp at the next token: use the key's.
          SourceMark value_fallback = key_mark;
          ConfigNode converted = Convert(value, value_fallback, depth + 1);
          if (value.IsNull() && converted.mark.line != key_mark.line) converted.mark = key_mark;
          out.entries.push_back(ConfigEntry{key.Scalar(), key_mark, std::move(converted)});
        }
        return out;
      }
      case YAML::NodeType::Null:
      case YAML::NodeType::Undefined:
        break;
    }
    ConfigNode null_node;
    null_node.mark = mark;
    return null_node;
  }

 private:
  const std::string& source_;
  std::vector<ConfigProblem>* problems_;
  std::size_t count_ = 0;
  bool stopped_ = false;
};

// Records where each document starts; ignores everything else.
class DocumentStarts : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark& mark) override { starts.push_back(mark); }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}

  std::vector<YAML::Mark> starts;
};

// Where the first two documents of `text` start (one config is one
// document; a second one is an error, so counting stops there). yaml-cpp
// 0.7.0 (Debian 12's) cannot be trusted with YAML::LoadAll: on a document
// that starts with a flow indicator such as `,` its parser returns an empty
// document without consuming the character, forever, and LoadAll allocates
// until the machine runs out of memory. A document that starts where the
// previous one did is that stuck parser: `*stuck` is set and counting stops.
// Throws YAML::Exception on ordinary syntax errors.
std::vector<YAML::Mark> DocumentStartMarks(const std::string& text, bool* stuck) {
  std::istringstream stream(text);
  YAML::Parser parser(stream);
  DocumentStarts handler;
  *stuck = false;
  while (handler.starts.size() < 2 && parser.HandleNextDocument(handler)) {
    const std::size_t n = handler.starts.size();
    *stuck = n == 2 && handler.starts[1].pos == handler.starts[0].pos;
  }
  return handler.starts;
}

// yaml-cpp's messages for a tab in the indentation often name something
// else ("illegal map value"): when line `line` (1-based) or the one before
// it is indented with a tab, says so.
std::string TabHint(const std::string& text, int line) {
  std::istringstream lines(text);
  std::string current;
  for (int n = 1; std::getline(lines, current) && n <= line; ++n) {
    if (n < line - 1) continue;
    const std::size_t indent_end = current.find_first_not_of(" \t");
    if (current.substr(0, indent_end).find('\t') != std::string::npos) {
      return " (line " + std::to_string(n) + " is indented with a tab: YAML indents with spaces only)";
    }
  }
  return "";
}

}  // namespace

ConfigNode ParseYaml(const std::string& text, const std::string& source,
                     std::vector<ConfigProblem>* problems) {
  const SourceMark start{source, 1, 1};
  std::vector<YAML::Mark> starts;
  bool stuck = false;
  YAML::Node document;
  try {
    starts = DocumentStartMarks(text, &stuck);
    if (!starts.empty() && !stuck) document = YAML::Load(text);  // the first document
  } catch (const YAML::Exception& error) {
    // yaml-cpp marks are 0-based.
    SourceMark mark{source, 0, 0};
    if (!error.mark.is_null() && error.mark.line >= 0) {
      mark.line = error.mark.line + 1;
      mark.column = error.mark.column + 1;
    }
    problems->push_back({mark, "", "YAML syntax error: " + error.msg + TabHint(text, mark.line)});
    ConfigNode null_node;
    null_node.mark = start;
    return null_node;
  }

  Converter converter(source, problems);
  if (stuck) {
    const SourceMark mark = converter.Mark(starts[1], start);
    const std::size_t pos = static_cast<std::size_t>(starts[1].pos);
    const std::string character = pos < text.size() ? text.substr(pos, 1) : std::string();
    problems->push_back({mark, "",
                         "YAML syntax error: a document cannot start with '" + character + "'"});
    ConfigNode null_node;
    null_node.mark = start;
    return null_node;
  }
  // One document per configuration.
  if (starts.size() > 1) {
    problems->push_back({converter.Mark(starts[1], start), "",
                         "expected one YAML document (a second one starts here)"});
  }
  if (starts.empty()) {
    ConfigNode null_node;
    null_node.mark = start;
    return null_node;
  }
  return converter.Convert(document, start, 0);
}

}  // namespace mjslam::config
