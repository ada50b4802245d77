#include "python/python_values.h"

#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <optional>
#include <variant>

#include "config/yaml_reader.h"

namespace py = pybind11;

namespace linesim::python {

namespace {

// Deeper than any scenario file (the repository's deepest is 6 levels): a
// dict that contains itself ends here instead of in a stack overflow.
constexpr int kMaxDepth = 64;

std::string TypeName(py::handle value) {
  return py::str(py::type::handle_of(value).attr("__qualname__")).cast<std::string>();
}

// The text of a scalar the loader reads back to the same value.
std::optional<std::string> ScalarText(py::handle value) {
  if (value.is_none()) return std::nullopt;
  const std::string type = TypeName(value);
  if (py::isinstance<py::bool_>(value) || type == "bool_") {
    return value.cast<bool>() ? "true" : "false";
  }
  if (py::isinstance<py::str>(value)) return value.cast<std::string>();
  if (PyIndex_Check(value.ptr()) != 0) {
    return py::str(py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr())))
        .cast<std::string>();
  }
  if (PyFloat_Check(value.ptr()) != 0 || py::hasattr(value, "__float__")) {
    const double x = value.cast<double>();
    if (std::isnan(x)) return ".nan";
    if (std::isinf(x)) return x > 0 ? ".inf" : "-.inf";
    // repr: the shortest text that reads back as the same double.
    return py::repr(py::float_(x)).cast<std::string>();
  }
  return std::nullopt;
}

class TreeBuilder {
 public:
  explicit TreeBuilder(std::vector<config::Issue>& issues) : issues_(issues) {}

  YAML::Node Build(py::handle value, const std::string& path, int depth) {
    if (depth > kMaxDepth) {
      Issue(path, "nested deeper than " + std::to_string(kMaxDepth) +
                      " levels (a dict or list that contains itself?)");
      return YAML::Node();
    }
    if (value.is_none()) return YAML::Node(YAML::NodeType::Null);
    if (py::isinstance<py::dict>(value))
      return Map(py::reinterpret_borrow<py::dict>(value), path, depth);
    if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
      YAML::Node seq(YAML::NodeType::Sequence);
      std::size_t i = 0;
      for (const py::handle item : value) {
        seq.push_back(Build(item, config::JoinPath(path, std::to_string(i++)), depth + 1));
      }
      return seq;
    }
    // A path object, a numpy array: as its Python value.
    if (py::hasattr(value, "__fspath__")) {
      return Build(py::module_::import("os").attr("fspath")(value), path, depth + 1);
    }
    if (py::hasattr(value, "tolist") && !py::isinstance<py::str>(value)) {
      return Build(value.attr("tolist")(), path, depth + 1);
    }
    if (const auto text = ScalarText(value)) return YAML::Node(*text);
    Issue(path, "a " + TypeName(value) + " (" + py::repr(value).cast<std::string>() +
                    ") is not a scenario value: expected a dict, a list, a str, a number, "
                    "true/false or None");
    return YAML::Node();
  }

 private:
  YAML::Node Map(const py::dict& dict, const std::string& path, int depth) {
    YAML::Node map(YAML::NodeType::Map);
    for (const auto& [key, item] : dict) {
      if (!py::isinstance<py::str>(key)) {
        Issue(path, "the key " + py::repr(key).cast<std::string>() + " (a " + TypeName(key) +
                        ") is not a str: keys are names, as in a file");
        continue;
      }
      const std::string name = key.cast<std::string>();
      map[name] = Build(item, config::JoinPath(path, name), depth + 1);
    }
    return map;
  }

  void Issue(const std::string& path, const std::string& message) {
    config::Issue issue;
    issue.file = kDictLabel;
    issue.key_path = path;
    issue.message = message;
    issues_.push_back(std::move(issue));
  }

  std::vector<config::Issue>& issues_;
};

}  // namespace

YAML::Node TreeFromPython(py::handle value, std::vector<config::Issue>& issues) {
  if (!py::isinstance<py::dict>(value)) {
    config::Issue issue;
    issue.file = kDictLabel;
    issue.message = "a scenario given as data must be a dict, got a " + TypeName(value);
    issues.push_back(std::move(issue));
    return YAML::Node();
  }
  return TreeBuilder(issues).Build(value, "", 0);
}

py::object ToPython(const cosim::Value& value) {
  return std::visit([](const auto& v) -> py::object { return py::cast(v); }, value);
}

std::string MetricKind(const cosim::MetricSpec& metric) {
  const bool extreme =
      metric.reduction == cosim::Reduction::kFinal || metric.reduction == cosim::Reduction::kMin ||
      metric.reduction == cosim::Reduction::kMax || metric.reduction == cosim::Reduction::kMaxAbs;
  if (extreme && metric.probe.type == cosim::VarType::kInteger) return "int";
  if (extreme && metric.probe.type == cosim::VarType::kBoolean) return "bool";
  return "float";
}

py::object TypedMetric(const std::string& kind, double value) {
  if (kind == "float") return py::float_(value);
  if (!std::isfinite(value)) return py::none();
  if (kind == "bool") return py::bool_(value != 0.0);
  return py::int_(static_cast<std::int64_t>(std::llround(value)));
}

py::list TypedParameterColumn(const std::vector<std::string>& texts) {
  enum Kind { kInt, kFloat, kBool, kText };
  // The narrowest kind every value reads as.
  const auto kind_of = [](const std::string& text) {
    if (text == "true" || text == "false" || text == "True" || text == "False" || text == "TRUE" ||
        text == "FALSE") {
      return kBool;
    }
    YAML::Node node;
    try {
      node = YAML::Load(text);
    } catch (const YAML::Exception&) {
      return kText;
    }
    std::int64_t i = 0;
    if (node.IsScalar() && YAML::convert<std::int64_t>::decode(node, i)) return kInt;
    if (config::YamlReader::DecodeReal(node)) return kFloat;
    return kText;
  };
  Kind column = kInt;
  bool any = false;
  for (const std::string& text : texts) {
    if (text.empty()) continue;
    const Kind k = kind_of(text);
    column = !any                                                                   ? k
             : k == column                                                          ? column
             : ((k == kInt || k == kFloat) && (column == kInt || column == kFloat)) ? kFloat
                                                                                    : kText;
    any = true;
  }
  py::list values;
  for (const std::string& text : texts) {
    if (text.empty()) {
      values.append(py::none());
      continue;
    }
    switch (column) {
      case kInt:
        values.append(YAML::Load(text).as<std::int64_t>());
        break;
      case kFloat:
        values.append(*config::YamlReader::DecodeReal(YAML::Load(text)));
        break;
      case kBool:
        values.append(text[0] == 't' || text[0] == 'T');
        break;
      case kText:
        values.append(text);
        break;
    }
  }
  return values;
}

}  // namespace linesim::python
