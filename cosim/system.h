#pragma once

#include <cstddef>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "cosim/time.h"
#include "cosim/unit.h"

namespace linesim::cosim {

/// True for a valid unit or variable name: letters, digits and '_'.
bool IsIdentifier(std::string_view s);
/// True for a valid unit name: identifiers joined by '.', the scope first
/// (a fleet's `raw3_a.chassis`; most units have no scope).
bool IsUnitName(std::string_view s);

/// One end of a connection: `unit.variable` or `unit.variable[index]` for
/// (the unit's name may be scoped: the variable is after the last '.')
///
/// one element of a real array.
struct Endpoint {
  std::string unit;
  std::string variable;
  std::optional<std::size_t> index;

  /// Parses "unit.variable" or "unit.variable[3]"; throws
  /// std::invalid_argument saying what was expected.
  static Endpoint Parse(std::string_view text);
  std::string ToString() const;
};

struct Connection {
  Endpoint from;
  Endpoint to;
};

/// One problem found while building a system or a master; `connection` and
/// `unit` are the indices of the connection or unit it concerns, when it
/// concerns one (so that a loader can point at its line in the file).
struct Problem {
  Problem(std::string message_text, std::optional<std::size_t> connection_index = std::nullopt,
          std::optional<std::size_t> unit_index = std::nullopt)
      : message(std::move(message_text)), connection(connection_index), unit(unit_index) {}
  std::string message;
  std::optional<std::size_t> connection;
  std::optional<std::size_t> unit;
};

/// Every problem found at once, never just the first.
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<Problem> problems);
  const std::vector<Problem>& problems() const { return problems_; }

 private:
  std::vector<Problem> problems_;
};

/// A connection after checking, resolved to unit indices and value refs.
struct Link {
  std::size_t from_unit = 0;
  std::size_t to_unit = 0;
  ValueRef from_ref = 0;
  ValueRef to_ref = 0;
  VarType type = VarType::kReal;
  /// Element of a real array at either end, or -1 for the whole variable.
  std::ptrdiff_t from_index = -1;
  std::ptrdiff_t to_index = -1;
};

/// Units and the connections between them. Build() checks the whole graph.
class System {
 public:
  /// `step` is the unit's communication step; 0 means the master's base step.
  Unit& Add(std::unique_ptr<Unit> unit, TimeNs step = 0);
  void Connect(Endpoint from, Endpoint to);
  void Connect(std::string_view from, std::string_view to);

  /// Checks names, causality, types, array sizes, units of measure, inputs
  /// with two sources and algebraic loops; throws ConfigError listing every
  /// problem. Also computes the Gauss-Seidel order.
  void Build();
  bool built() const { return built_; }

  std::size_t unit_count() const { return units_.size(); }
  Unit& unit(std::size_t i) { return *units_[i].unit; }
  const Unit& unit(std::size_t i) const { return *units_[i].unit; }
  TimeNs unit_step(std::size_t i) const { return units_[i].step; }
  std::optional<std::size_t> FindUnit(std::string_view name) const;
  std::vector<std::string> UnitNames() const;

  const std::vector<Connection>& connections() const { return connections_; }
  /// Valid after Build(): one link per connection, in the same order.
  const std::vector<Link>& links() const { return links_; }
  /// Valid after Build(): units in dependency order (sources before the
  /// units they feed; inside a feedback loop, units with direct feedthrough
  /// after the units that feed them, then declaration order).
  const std::vector<std::size_t>& dependency_order() const { return order_; }

  /// Resolves "unit.variable" or "unit.variable[i]" to a unit index, value
  /// ref and element index (-1 for a whole variable); throws ConfigError
  /// with the closest names when it does not exist.
  struct Resolved {
    std::size_t unit;
    ValueRef ref;
    std::ptrdiff_t index;
  };
  Resolved Resolve(std::string_view endpoint) const;

 private:
  struct Entry {
    std::unique_ptr<Unit> unit;
    TimeNs step;
  };
  std::optional<Link> CheckConnection(std::size_t c, std::vector<Problem>& problems) const;
  void CheckAlgebraicLoops(std::vector<Problem>& problems) const;
  void ComputeOrder();

  std::vector<Entry> units_;
  std::vector<Connection> connections_;
  std::vector<Link> links_;
  std::vector<std::size_t> order_;
  bool built_ = false;
};

}  // namespace linesim::cosim
