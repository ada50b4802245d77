#pragma once

// Python values to and from what the loader and the units hold: a dict
// given as a scenario becomes the YAML tree a file would give (no file in
// between), and values go back to Python in their types.
#include <pybind11/pybind11.h>
#include <yaml-cpp/yaml.h>

#include <string>
#include <vector>

#include "config/scenario_error.h"
#include "cosim/observers.h"
#include "cosim/variable_table.h"

namespace linesim::python {

/// What issues name a scenario or sweep given as a dict by, where a file's
/// path would be.
inline constexpr const char* kDictLabel = "<dict>";

/// The YAML tree of `value` (a dict of the files' schema): dicts, lists and
/// tuples, str, int, float (inf and nan as YAML writes them), bool, None,
/// os.PathLike (its path), numpy scalars and arrays (as their Python
/// values). Anything else, a key that is not a str, and nesting deeper than
/// a file could be, are issues at their key path (file kDictLabel, no
/// line); the tree is only meaningful when `issues` stayed empty.
YAML::Node TreeFromPython(pybind11::handle value, std::vector<config::Issue>& issues);

/// A variable's value in its Python type: float, int, bool, str, or a list
/// of floats.
pybind11::object ToPython(const cosim::Value& value);

/// How a metric's number is given to Python: "int" (the final, smallest or
/// largest value of an Integer variable: a count), "bool" (of a Boolean),
/// else "float".
std::string MetricKind(const cosim::MetricSpec& metric);
/// `value` as `kind` says: an int or a bool when it is finite, None when a
/// count or a flag has no value (a failed run's NaN), else a float.
pybind11::object TypedMetric(const std::string& kind, double value);

/// A sweep parameter's values (YAML text, "" for none) as the loader reads
/// them, one type for the column: int when every value is an integer,
/// float when every value is a number, bool when every value is true or
/// false, else the text; None where a run has no value.
pybind11::list TypedParameterColumn(const std::vector<std::string>& texts);

}  // namespace linesim::python
