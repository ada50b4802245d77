#include "loader/overrides.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <map>
#include <optional>
#include <string_view>

#include "loader/config_names.h"

namespace linesim::loader {

namespace {

std::vector<std::string> Split(const std::string& path) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const auto dot = path.find('.', start);
    parts.push_back(path.substr(start, dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return parts;
}

bool IsIndex(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c));
  });
}

// The list index `s` stands for, if it is one below `size`.
std::optional<std::size_t> IndexBelow(const std::string& s, std::size_t size) {
  if (!IsIndex(s)) return std::nullopt;
  std::size_t index = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), index);
  if (ec != std::errc() || end != s.data() + s.size() || index >= size) return std::nullopt;
  return index;
}

// A value meant as a YAML list, map or quoted string.
bool LooksStructured(const std::string& value) {
  const auto first = value.find_first_not_of(" \t");
  return first != std::string::npos &&
         std::string_view("[{\"'").find(value[first]) != std::string_view::npos;
}

}  // namespace

Override ParseOverride(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) {
    throw ScenarioError(
        {{"", 0, "--set " + text, "expected dotted.path=value (for example master.step_s=0.002)"}});
  }
  return {text.substr(0, eq), text.substr(eq + 1)};
}

namespace {

// Positions in the file of the nodes the tree reaches more than once: an
// anchored value and its aliases are one node in yaml-cpp, so writing into
// it through one path changes it at every other. Each node is entered once.
void CountVisits(const YAML::Node& node, std::map<std::size_t, int>& visits) {
  const YAML::Mark mark = node.Mark();
  if (!mark.is_null() && ++visits[static_cast<std::size_t>(mark.pos)] > 1) return;
  if (node.IsMap()) {
    for (const auto& kv : node) CountVisits(kv.second, visits);
  } else if (node.IsSequence()) {
    for (const auto& item : node) CountVisits(item, visits);
  }
}

bool Shared(const YAML::Node& node, const std::map<std::size_t, int>& visits) {
  if (!node.IsDefined() || node.Mark().is_null()) return false;
  const auto it = visits.find(static_cast<std::size_t>(node.Mark().pos));
  return it != visits.end() && it->second > 1;
}

}  // namespace

void RefuseOverridesThroughAliases(const YAML::Node& root, const std::vector<Override>& overrides,
                                   const std::string& file, std::vector<Issue>& issues) {
  if (overrides.empty()) return;
  std::map<std::size_t, int> visits;
  CountVisits(root, visits);
  for (const Override& o : overrides) {
    YAML::Node node = root;
    std::string walked;
    for (const std::string& key : Split(o.path)) {
      const YAML::Node& cnode = node;
      const auto child_of = [&]() -> YAML::Node {
        if (cnode.IsSequence()) {
          if (const auto index = IndexBelow(key, cnode.size())) return cnode[*index];
        } else if (cnode.IsMap()) {
          return cnode[key];
        }
        return YAML::Node();
      };
      const YAML::Node child = child_of();
      if (!child.IsDefined()) break;  // ApplyOverrides reports a bad path
      walked = JoinPath(walked, key);
      if (Shared(child, visits)) {
        issues.push_back(
            {file, 0, o.path,
             "'" + walked +
                 "' is a value the file uses again through a YAML alias (its anchor "
                 "at line " +
                 std::to_string(child.Mark().line + 1) +
                 "): setting it would change every place the alias stands; write the value "
                 "out where it is meant to differ (in --set " +
                 o.path + "=" + o.value + ")",
             true, false});
        break;
      }
      node.reset(child);
    }
  }
}

void ApplyOverrides(YAML::Node& root, const std::vector<Override>& overrides,
                    const std::string& file, std::vector<Issue>& issues) {
  for (const Override& o : overrides) {
    const auto report = [&](const std::string& message) {
      issues.push_back(
          {file, 0, o.path, message + " (in --set " + o.path + "=" + o.value + ")", true, true});
    };
    const std::vector<std::string> parts = Split(o.path);
    if (std::any_of(parts.begin(), parts.end(), [](const std::string& p) { return p.empty(); })) {
      report("empty key in the path");
      continue;
    }
    YAML::Node value;
    try {
      value = o.value.empty() ? YAML::Node(YAML::NodeType::Null) : YAML::Load(o.value);
    } catch (const YAML::Exception& e) {
      // Plain text that YAML refuses ("a: b: c") is meant as a string; a
      // list, map or quoted string that does not parse is a typo.
      if (LooksStructured(o.value)) {
        // A bad value at a path that may well be right.
        issues.push_back(
            {file, 0, o.path,
             "value is not valid YAML: " + e.msg + " (in --set " + o.path + "=" + o.value + ")",
             true, false});
        continue;
      }
      value = YAML::Node(o.value);
    }

    // Walk with copies of node handles (yaml-cpp nodes are references).
    YAML::Node node = root;
    std::string walked;
    bool ok = true;
    for (std::size_t i = 0; i < parts.size() && ok; ++i) {
      const std::string& key = parts[i];
      const bool last = i + 1 == parts.size();
      if (node.IsSequence()) {
        const std::optional<std::size_t> index = IndexBelow(key, node.size());
        if (!index) {
          report("'" + JoinPath(walked, key) + "' is not an item of the list at '" + walked +
                 "', which has " + std::to_string(node.size()) + " items (0 to " +
                 std::to_string(node.size() == 0 ? 0 : node.size() - 1) + ")");
          ok = false;
          break;
        }
        if (last) {
          node[*index] = value;
        } else {
          node.reset(node[*index]);
        }
      } else if (node.IsMap() || (node.IsNull() && last)) {
        const YAML::Node& cnode = node;
        const bool exists = cnode.IsMap() && cnode[key].IsDefined();
        if (last) {
          node[key] = value;
        } else if (!exists) {
          std::vector<std::string> keys;
          for (const auto& kv : cnode) keys.push_back(kv.first.Scalar());
          const bool item_next = i + 2 == parts.size() && IsIndex(parts[i + 1]);
          report("no key '" + key + "' at '" + (walked.empty() ? "(top)" : walked) + "'" +
                 ClosestPathsHint(walked, key, keys) +
                 (item_next ? "; one item can be set only where the file writes the list: "
                              "set the whole value instead, e.g. " +
                                  JoinPath(walked, key) + "=[...]"
                            : ""));
          ok = false;
          break;
        } else {
          node.reset(node[key]);
        }
      } else {
        report("'" + walked + "' holds a value, not a map or list, so it has no key '" + key + "'");
        ok = false;
      }
      walked = JoinPath(walked, key);
    }
  }
}

}  // namespace linesim::loader
