#include "cosim/system.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <functional>
#include <map>
#include <set>

#include "cosim/closest_names.h"

namespace linesim::cosim {

bool IsIdentifier(std::string_view s) {
  if (s.empty()) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
  });
}

bool IsUnitName(std::string_view s) {
  for (;;) {
    const auto dot = s.find('.');
    if (!IsIdentifier(s.substr(0, dot))) return false;
    if (dot == std::string_view::npos) return true;
    s.remove_prefix(dot + 1);
  }
}

namespace {

std::string JoinProblems(const std::vector<Problem>& problems) {
  std::string out;
  for (const auto& p : problems) out += (out.empty() ? "" : "\n") + p.message;
  return out;
}

}  // namespace

ConfigError::ConfigError(std::vector<Problem> problems)
    : std::runtime_error(JoinProblems(problems)), problems_(std::move(problems)) {}

Endpoint Endpoint::Parse(std::string_view text) {
  const auto fail = [&]() -> Endpoint {
    throw std::invalid_argument("'" + std::string(text) +
                                "' is not an endpoint: expected unit.variable or "
                                "unit.variable[index]");
  };
  // The variable is after the unit's last '.' (a scoped unit has several);
  // an index's brackets hold no '.'.
  const auto dot = text.substr(0, text.find('[')).rfind('.');
  if (dot == std::string_view::npos) return fail();
  Endpoint e;
  e.unit = std::string(text.substr(0, dot));
  std::string_view rest = text.substr(dot + 1);
  if (const auto open = rest.find('['); open != std::string_view::npos) {
    if (rest.back() != ']' || open + 2 > rest.size() - 1) return fail();
    const std::string_view digits = rest.substr(open + 1, rest.size() - open - 2);
    if (!std::all_of(digits.begin(), digits.end(),
                     [](char c) { return std::isdigit(static_cast<unsigned char>(c)); })) {
      return fail();
    }
    // from_chars, not stoul: an index too large for size_t is a malformed
    // endpoint (std::invalid_argument), not std::out_of_range.
    std::size_t index = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), index);
    if (ec != std::errc() || end != digits.data() + digits.size()) return fail();
    e.index = index;
    rest = rest.substr(0, open);
  }
  e.variable = std::string(rest);
  if (!IsUnitName(e.unit) || !IsIdentifier(e.variable)) return fail();
  return e;
}

std::string Endpoint::ToString() const {
  std::string s = unit + "." + variable;
  if (index) s += "[" + std::to_string(*index) + "]";
  return s;
}

Unit& System::Add(std::unique_ptr<Unit> unit, TimeNs step) {
  built_ = false;
  units_.push_back({std::move(unit), step});
  return *units_.back().unit;
}

void System::Connect(Endpoint from, Endpoint to) {
  built_ = false;
  connections_.push_back({std::move(from), std::move(to)});
}

void System::Connect(std::string_view from, std::string_view to) {
  Connect(Endpoint::Parse(from), Endpoint::Parse(to));
}

std::optional<std::size_t> System::FindUnit(std::string_view name) const {
  for (std::size_t i = 0; i < units_.size(); ++i) {
    if (units_[i].unit->name() == name) return i;
  }
  return std::nullopt;
}

std::vector<std::string> System::UnitNames() const {
  std::vector<std::string> names;
  for (const auto& e : units_) names.push_back(e.unit->name());
  return names;
}

System::Resolved System::Resolve(std::string_view text) const {
  Endpoint e;
  try {
    e = Endpoint::Parse(text);
  } catch (const std::invalid_argument& ex) {
    throw ConfigError({{ex.what(), std::nullopt}});
  }
  const auto u = FindUnit(e.unit);
  if (!u) {
    throw ConfigError({{"unknown unit '" + e.unit + "' in '" + std::string(text) + "'" +
                            ClosestHint(e.unit, UnitNames()),
                        std::nullopt}});
  }
  const VariableTable& table = unit(*u).variables();
  const auto ref = table.Find(e.variable);
  if (!ref) {
    throw ConfigError({{"unit '" + e.unit + "' has no variable '" + e.variable + "'" +
                            ClosestHint(e.variable, table.Names()),
                        std::nullopt}});
  }
  const VariableInfo& info = table.info(*ref);
  if (e.index && (info.type != VarType::kRealArray || *e.index >= info.size)) {
    throw ConfigError(
        {{"'" + std::string(text) + "': " +
              (info.type == VarType::kRealArray ? "index out of range, " + e.variable + " has " +
                                                      std::to_string(info.size) + " elements"
                                                : e.variable + " is not an array"),
          std::nullopt}});
  }
  return {*u, *ref, e.index ? static_cast<std::ptrdiff_t>(*e.index) : -1};
}

std::optional<Link> System::CheckConnection(std::size_t c, std::vector<Problem>& problems) const {
  const Connection& conn = connections_[c];
  const std::string label = conn.from.ToString() + " -> " + conn.to.ToString();
  const auto report = [&](const std::string& message) {
    problems.push_back({"connection " + label + ": " + message, c});
  };

  struct End {
    std::size_t unit;
    const VariableInfo* info;
  };
  const auto resolve = [&](const Endpoint& e, Causality wanted) -> std::optional<End> {
    const auto u = FindUnit(e.unit);
    if (!u) {
      report("unknown unit '" + e.unit + "'" + ClosestHint(e.unit, UnitNames()));
      return std::nullopt;
    }
    const VariableTable& table = unit(*u).variables();
    const auto ref = table.Find(e.variable);
    if (!ref) {
      std::vector<std::string> same_causality;
      for (const auto& i : table.infos()) {
        if (i.causality == wanted) same_causality.push_back(i.name);
      }
      report("unit '" + e.unit + "' (" + unit(*u).type_name() + ") has no variable '" + e.variable +
             "'" + ClosestHint(e.variable, same_causality));
      return std::nullopt;
    }
    const VariableInfo& info = table.info(*ref);
    if (info.causality == Causality::kParameter && wanted == Causality::kInput) {
      // A parameter keeps its value over the run (fixed, or tunable between
      // steps by the master, never by a signal): it cannot be a target.
      report(e.unit + "." + e.variable +
             " is a parameter: parameters are set before the run (under parameters:), "
             "not connected; a connection must go from an output to an input");
      return std::nullopt;
    }
    if (info.causality != wanted) {
      report(e.unit + "." + e.variable + " is " + std::string(ToString(info.causality)) +
             ", a connection must go from an output to an input");
      return std::nullopt;
    }
    if (e.index) {
      if (info.type != VarType::kRealArray) {
        report(e.ToString() + ": " + e.variable + " is " + std::string(ToString(info.type)) +
               ", not an array, so it takes no index");
        return std::nullopt;
      }
      if (*e.index >= info.size) {
        report(e.ToString() + ": index out of range, " + e.variable + " has " +
               std::to_string(info.size) + " elements");
        return std::nullopt;
      }
    }
    return End{*u, &info};
  };

  const auto from = resolve(conn.from, Causality::kOutput);
  const auto to = resolve(conn.to, Causality::kInput);
  if (!from || !to) return std::nullopt;

  // An array element is a Real scalar on the other side.
  const auto effective = [](const End& e, const Endpoint& ep) {
    return (e.info->type == VarType::kRealArray && ep.index) ? VarType::kReal : e.info->type;
  };
  const VarType from_type = effective(*from, conn.from);
  const VarType to_type = effective(*to, conn.to);
  bool ok = true;
  if (from_type != to_type) {
    report("type mismatch: " + conn.from.ToString() + " is " + std::string(ToString(from_type)) +
           ", " + conn.to.ToString() + " is " + std::string(ToString(to_type)));
    ok = false;
  } else if (from_type == VarType::kRealArray && from->info->size != to->info->size) {
    report("array size mismatch: " + conn.from.ToString() + " has " +
           std::to_string(from->info->size) + " elements, " + conn.to.ToString() + " has " +
           std::to_string(to->info->size));
    ok = false;
  }
  if (from->info->unit != to->info->unit) {
    report("units of measure differ: " + conn.from.ToString() + " is in '" + from->info->unit +
           "', " + conn.to.ToString() + " is in '" + to->info->unit + "'");
    ok = false;
  }
  if (!ok) return std::nullopt;
  Link link;
  link.from_unit = from->unit;
  link.to_unit = to->unit;
  link.from_ref = from->info->ref;
  link.to_ref = to->info->ref;
  link.type = from_type == VarType::kReal && (conn.from.index || conn.to.index) ? VarType::kReal
                                                                                : from->info->type;
  link.from_index = conn.from.index ? static_cast<std::ptrdiff_t>(*conn.from.index) : -1;
  link.to_index = conn.to.index ? static_cast<std::ptrdiff_t>(*conn.to.index) : -1;
  return link;
}

void System::CheckAlgebraicLoops(std::vector<Problem>& problems) const {
  // Nodes are variables (unit, ref). Edges: a connection output -> input, and
  // inside a unit, input -> each output that depends on it directly. A cycle
  // is a loop that no unit breaks with state: an algebraic loop.
  using Node = std::pair<std::size_t, ValueRef>;
  std::map<Node, std::vector<Node>> edges;
  for (const Link& l : links_) {
    edges[{l.from_unit, l.from_ref}].push_back({l.to_unit, l.to_ref});
  }
  for (std::size_t u = 0; u < units_.size(); ++u) {
    for (const auto& info : unit(u).variables().infos()) {
      for (ValueRef in : info.depends_on) edges[{u, in}].push_back({u, info.ref});
    }
  }
  const auto name = [&](const Node& n) {
    return unit(n.first).name() + "." + unit(n.first).variables().info(n.second).name;
  };

  std::map<Node, int> color;  // 0 new, 1 on the stack, 2 done
  std::vector<Node> stack;
  std::set<std::string> reported;
  std::function<void(const Node&)> visit = [&](const Node& n) {
    color[n] = 1;
    stack.push_back(n);
    if (auto it = edges.find(n); it != edges.end()) {
      for (const Node& next : it->second) {
        if (color[next] == 1) {
          auto begin = std::find(stack.begin(), stack.end(), next);
          std::string cycle;
          for (auto p = begin; p != stack.end(); ++p) cycle += name(*p) + " -> ";
          cycle += name(next);
          if (reported.insert(cycle).second) {
            problems.push_back({"algebraic loop (every step of it is direct feedthrough): " + cycle,
                                std::nullopt});
          }
        } else if (color[next] == 0) {
          visit(next);
        }
      }
    }
    stack.pop_back();
    color[n] = 2;
  };
  for (const auto& [node, targets] : edges) {
    if (color[node] == 0) visit(node);
  }
}

void System::ComputeOrder() {
  const std::size_t n = units_.size();
  // A "strong" edge ends on an input that some output depends on directly:
  // the destination must step after the source to see its new value.
  std::vector<std::set<std::size_t>> succ(n), strong(n);
  for (const Link& l : links_) {
    if (l.from_unit == l.to_unit) continue;
    succ[l.from_unit].insert(l.to_unit);
    for (const auto& info : unit(l.to_unit).variables().infos()) {
      if (std::find(info.depends_on.begin(), info.depends_on.end(), l.to_ref) !=
          info.depends_on.end()) {
        strong[l.from_unit].insert(l.to_unit);
      }
    }
  }
  // Strongly connected components (Tarjan), so that feedback loops order as
  // blocks.
  std::vector<int> index(n, -1), low(n, 0), comp(n, -1);
  std::vector<bool> on_stack(n, false);
  std::vector<std::size_t> stack;
  int counter = 0, comps = 0;
  std::function<void(std::size_t)> strongconnect = [&](std::size_t v) {
    index[v] = low[v] = counter++;
    stack.push_back(v);
    on_stack[v] = true;
    for (std::size_t w : succ[v]) {
      if (index[w] < 0) {
        strongconnect(w);
        low[v] = std::min(low[v], low[w]);
      } else if (on_stack[w]) {
        low[v] = std::min(low[v], index[w]);
      }
    }
    if (low[v] == index[v]) {
      std::size_t w;
      do {
        w = stack.back();
        stack.pop_back();
        on_stack[w] = false;
        comp[w] = comps;
      } while (w != v);
      ++comps;
    }
  };
  for (std::size_t v = 0; v < n; ++v) {
    if (index[v] < 0) strongconnect(v);
  }
  // Kahn's algorithm over units, where an edge counts if it joins two
  // components or is strong inside one; ties go to declaration order.
  std::vector<std::set<std::size_t>> dag(n);
  std::vector<int> indegree(n, 0);
  for (std::size_t v = 0; v < n; ++v) {
    for (std::size_t w : succ[v]) {
      if (comp[v] != comp[w] || strong[v].count(w)) {
        if (dag[v].insert(w).second) ++indegree[w];
      }
    }
  }
  std::set<std::size_t> ready;
  for (std::size_t v = 0; v < n; ++v) {
    if (indegree[v] == 0) ready.insert(v);
  }
  order_.clear();
  while (!ready.empty()) {
    const std::size_t v = *ready.begin();
    ready.erase(ready.begin());
    order_.push_back(v);
    for (std::size_t w : dag[v]) {
      if (--indegree[w] == 0) ready.insert(w);
    }
  }
  // Without algebraic loops the graph is acyclic; anything left (which the
  // loop check would already have reported) keeps declaration order.
  for (std::size_t v = 0; v < n; ++v) {
    if (std::find(order_.begin(), order_.end(), v) == order_.end()) order_.push_back(v);
  }
}

void System::Build() {
  std::vector<Problem> problems;
  std::set<std::string> seen;
  for (const auto& e : units_) {
    if (!IsUnitName(e.unit->name())) {
      problems.push_back(
          {"unit name '" + e.unit->name() +
               "' is not valid: use letters, digits and '_' (and '.' after a scope)",
           std::nullopt});
    }
    if (!seen.insert(e.unit->name()).second) {
      problems.push_back({"two units are named '" + e.unit->name() + "'", std::nullopt});
    }
    if (e.step < 0) {
      problems.push_back({"unit '" + e.unit->name() + "' has a negative step", std::nullopt});
    }
  }

  links_.clear();
  std::vector<std::optional<Link>> checked;
  for (std::size_t c = 0; c < connections_.size(); ++c) {
    checked.push_back(CheckConnection(c, problems));
  }

  // An input (or one element of it) may have only one source.
  std::map<std::pair<std::size_t, ValueRef>, std::vector<std::size_t>> sources;
  for (std::size_t c = 0; c < checked.size(); ++c) {
    if (checked[c]) sources[{checked[c]->to_unit, checked[c]->to_ref}].push_back(c);
  }
  for (const auto& [dst, conns] : sources) {
    for (std::size_t a = 0; a < conns.size(); ++a) {
      for (std::size_t b = a + 1; b < conns.size(); ++b) {
        const Link& la = *checked[conns[a]];
        const Link& lb = *checked[conns[b]];
        if (la.to_index < 0 || lb.to_index < 0 || la.to_index == lb.to_index) {
          problems.push_back({"input " + connections_[conns[b]].to.ToString() +
                                  " has two sources: " + connections_[conns[a]].from.ToString() +
                                  " and " + connections_[conns[b]].from.ToString(),
                              conns[b]});
        }
      }
    }
  }

  for (const auto& l : checked) {
    if (l) links_.push_back(*l);
  }
  CheckAlgebraicLoops(problems);
  if (!problems.empty()) {
    links_.clear();
    throw ConfigError(std::move(problems));
  }
  ComputeOrder();
  built_ = true;
}

}  // namespace linesim::cosim
