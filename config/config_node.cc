#include "config/config_node.h"

#include <cstdio>
#include <utility>

namespace mjslam::config {
namespace {

using Kind = ConfigNode::Kind;

// Characters that would end or restructure a plain scalar inside `[...]`.
bool IsFlowSafePlain(const std::string& text) {
  if (text.empty()) return false;
  return text.find_first_of(",[]{}#") == std::string::npos &&
         text.find(": ") == std::string::npos;
}

// A map key written plain: letters, digits, '_', '-', '.' only.
bool IsPlainKey(const std::string& key) {
  if (key.empty()) return false;
  for (char c : key) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                    (c >= '0' && c <= '9') || c == '_' || c == '-' || c == '.';
    if (!ok) return false;
  }
  return true;
}

// YAML double-quoted scalar with the escapes yaml-cpp reads back.
std::string DoubleQuoted(const std::string& text) {
  std::string out = "\"";
  for (char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (byte < 0x20 || byte == 0x7f) {
          char buffer[8];
          std::snprintf(buffer, sizeof(buffer), "\\x%02x", static_cast<unsigned>(byte));
          out += buffer;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

std::string ScalarText(const ConfigNode& node) {
  if (node.kind == Kind::kNull) return "null";
  if (node.quoted || node.scalar.empty()) return DoubleQuoted(node.scalar);
  return node.scalar;
}

std::string KeyText(const std::string& key) {
  return IsPlainKey(key) ? key : DoubleQuoted(key);
}

// A sequence written on one line: every item a null or a flow-safe scalar.
bool IsFlowSequence(const ConfigNode& node) {
  for (const ConfigNode& item : node.items) {
    if (item.kind == Kind::kNull) continue;
    if (item.kind != Kind::kScalar) return false;
    if (!item.quoted && !IsFlowSafePlain(item.scalar)) return false;
  }
  return true;
}

std::string FlowSequence(const ConfigNode& node) {
  std::string out = "[";
  for (std::size_t i = 0; i < node.items.size(); ++i) {
    if (i > 0) out += ", ";
    out += ScalarText(node.items[i]);
  }
  return out + "]";
}

void EmitBlock(const ConfigNode& node, int indent, std::string* out);

// The value after "key:" or "-": inline, or on the next lines indented.
void EmitValue(const ConfigNode& node, int indent, std::string* out) {
  switch (node.kind) {
    case Kind::kNull:
    case Kind::kScalar:
      *out += " " + ScalarText(node) + "\n";
      return;
    case Kind::kMap:
      if (node.entries.empty()) {
        *out += " {}\n";
        return;
      }
      break;
    case Kind::kSequence:
      if (IsFlowSequence(node)) {
        *out += " " + FlowSequence(node) + "\n";
        return;
      }
      break;
  }
  *out += "\n";
  EmitBlock(node, indent + 2, out);
}

// A non-empty map or a block sequence, one line per entry or item.
void EmitBlock(const ConfigNode& node, int indent, std::string* out) {
  const std::string pad(static_cast<std::size_t>(indent), ' ');
  if (node.kind == Kind::kMap) {
    for (const ConfigEntry& entry : node.entries) {
      *out += pad + KeyText(entry.key) + ":";
      EmitValue(entry.value, indent, out);
    }
  } else {
    for (const ConfigNode& item : node.items) {
      *out += pad + "-";
      EmitValue(item, indent, out);
    }
  }
}

}  // namespace

std::string FormatMark(const SourceMark& mark) {
  if (mark.line <= 0) return mark.source;
  return mark.source + ":" + std::to_string(mark.line) + ":" + std::to_string(mark.column);
}

ConfigNode ScalarNode(std::string text, bool quoted, SourceMark mark) {
  ConfigNode node;
  node.kind = Kind::kScalar;
  node.scalar = std::move(text);
  node.quoted = quoted;
  node.mark = std::move(mark);
  return node;
}

ConfigNode SequenceNode(SourceMark mark) {
  ConfigNode node;
  node.kind = Kind::kSequence;
  node.mark = std::move(mark);
  return node;
}

ConfigNode MapNode(SourceMark mark) {
  ConfigNode node;
  node.kind = Kind::kMap;
  node.mark = std::move(mark);
  return node;
}

std::string FormatProblem(const ConfigProblem& problem) {
  std::string out = FormatMark(problem.mark);
  if (!problem.key.empty()) out += (out.empty() ? "" : ": ") + problem.key;
  out += (out.empty() ? "" : ": ") + problem.message;
  return out;
}

namespace {
std::string JoinProblems(const std::vector<ConfigProblem>& problems) {
  std::string message;
  for (const ConfigProblem& problem : problems) {
    if (!message.empty()) message += "\n";
    message += FormatProblem(problem);
  }
  return message;
}
}  // namespace

ConfigError::ConfigError(std::vector<ConfigProblem> problems)
    : std::runtime_error(JoinProblems(problems)), problems_(std::move(problems)) {}

std::string EmitYaml(const ConfigNode& node) {
  std::string out;
  const bool block = (node.kind == Kind::kMap && !node.entries.empty()) ||
                     (node.kind == Kind::kSequence && !IsFlowSequence(node));
  if (block) {
    EmitBlock(node, 0, &out);
  } else {
    // A lone scalar, empty map or one-line sequence: EmitValue adds a leading space.
    EmitValue(node, 0, &out);
    out.erase(0, 1);
  }
  return out;
}

}  // namespace mjslam::config
