#pragma once
// The rules of the FMI 2.0 and 3.0 model description schemas (the XSDs'
// attribute types: fmi2ScalarVariable.xsd, fmi2Type.xsd, fmi3Variable.xsd,
// fmi3Type.xsd) and of the standards' text that the XSDs cannot express
// (FMI 2.0.4 section 2.2.7, FMI 3.0.2 section 2.4.7: min <= start <= max,
// units defined in UnitDefinitions, declared types in TypeDefinitions,
// start required or forbidden by causality, the causality / variability
// combinations, every output in ModelStructure), written out here because
// no validator of the XSDs is packaged for Debian. Used on the project's
// test FMUs and on every export (tests/fmu_export/).
#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <map>
#include <optional>
#include <pugixml.hpp>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace linesim::fmu::test {

// The value space of an XSD type an attribute takes.
enum class Xsd {
  kDouble,
  kFloat,
  kByte,
  kUByte,
  kShort,
  kUShort,
  kInt,
  kUInt,
  kLong,
  kULong,
  kBool
};

inline std::optional<double> ParseXsd(const std::string& text, Xsd type) {
  if (text.empty()) return std::nullopt;
  if (type == Xsd::kBool) {
    if (text == "true" || text == "1") return 1.0;
    if (text == "false" || text == "0") return 0.0;
    return std::nullopt;
  }
  if (type == Xsd::kDouble || type == Xsd::kFloat) {
    // xs:double's lexical space: a decimal or scientific number, or INF,
    // -INF, NaN (never "inf" or "nan", which C writes).
    if (text == "INF") return std::numeric_limits<double>::infinity();
    if (text == "-INF") return -std::numeric_limits<double>::infinity();
    if (text == "NaN") return std::numeric_limits<double>::quiet_NaN();
    if (text.find_first_not_of("0123456789+-.eE") != std::string::npos) return std::nullopt;
    char* end = nullptr;
    const double x = std::strtod(text.c_str(), &end);
    if (*end != '\0' || !std::isfinite(x)) return std::nullopt;
    if (type == Xsd::kFloat && std::fabs(x) > FLT_MAX) return std::nullopt;
    return x;
  }
  if (text.find_first_not_of("0123456789+-") != std::string::npos) return std::nullopt;
  errno = 0;
  char* end = nullptr;
  const bool is_unsigned =
      type == Xsd::kUByte || type == Xsd::kUShort || type == Xsd::kUInt || type == Xsd::kULong;
  if (is_unsigned) {
    if (text[0] == '-' && text.find_first_not_of("-0") != std::string::npos) return std::nullopt;
    const unsigned long long u = std::strtoull(text.c_str(), &end, 10);
    if (*end != '\0' || errno == ERANGE) return std::nullopt;
    const unsigned long long max = type == Xsd::kUByte    ? UINT8_MAX
                                   : type == Xsd::kUShort ? UINT16_MAX
                                   : type == Xsd::kUInt   ? UINT32_MAX
                                                          : UINT64_MAX;
    if (u > max) return std::nullopt;
    return static_cast<double>(u);
  }
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (*end != '\0' || errno == ERANGE) return std::nullopt;
  const long long lo = type == Xsd::kByte    ? INT8_MIN
                       : type == Xsd::kShort ? INT16_MIN
                       : type == Xsd::kInt   ? INT32_MIN
                                             : INT64_MIN;
  const long long hi = type == Xsd::kByte    ? INT8_MAX
                       : type == Xsd::kShort ? INT16_MAX
                       : type == Xsd::kInt   ? INT32_MAX
                                             : INT64_MAX;
  if (v < lo || v > hi) return std::nullopt;
  return static_cast<double>(v);
}

// Every way `xml` (a modelDescription.xml of FMI 2.0 or 3.0) breaks the
// rules, one line each naming the variable and attribute; empty when none.
inline std::vector<std::string> SchemaProblems(const std::string& xml) {
  std::vector<std::string> problems;
  const auto problem = [&](const std::string& where, const std::string& what) {
    problems.push_back(where + ": " + what);
  };
  pugi::xml_document doc;
  if (!doc.load_string(xml.c_str())) return {"not well-formed XML"};
  const pugi::xml_node root = doc.child("fmiModelDescription");
  const std::string version = root.attribute("fmiVersion").value();
  const bool v3 = version.rfind("3.", 0) == 0;
  if (version != "2.0" && !v3) return {"fmiVersion '" + version + "'"};
  for (const char* a : {"modelName", v3 ? "instantiationToken" : "guid"}) {
    if (!root.attribute(a)) problem("fmiModelDescription", std::string("no ") + a + " (required)");
  }
  if (!root.child("CoSimulation").attribute("modelIdentifier")) {
    problem("CoSimulation", "no modelIdentifier (required)");
  }
  std::set<std::string> units, types;
  for (const auto& u : root.child("UnitDefinitions").children("Unit")) {
    units.insert(u.attribute("name").value());
  }
  for (const auto& t : root.child("TypeDefinitions").children()) {
    types.insert(t.attribute("name").value());
  }
  // FMI 3.0's element name -> XSD type of min, max, nominal, start.
  static const std::map<std::string, Xsd> kTypes3 = {
      {"Float64", Xsd::kDouble}, {"Float32", Xsd::kFloat}, {"Int8", Xsd::kByte},
      {"UInt8", Xsd::kUByte},    {"Int16", Xsd::kShort},   {"UInt16", Xsd::kUShort},
      {"Int32", Xsd::kInt},      {"UInt32", Xsd::kUInt},   {"Int64", Xsd::kLong},
      {"UInt64", Xsd::kULong},   {"Boolean", Xsd::kBool},  {"Enumeration", Xsd::kLong}};
  static const std::map<std::string, Xsd> kTypes2 = {{"Real", Xsd::kDouble},
                                                     {"Integer", Xsd::kInt},
                                                     {"Enumeration", Xsd::kInt},
                                                     {"Boolean", Xsd::kBool}};
  static const std::set<std::string> kCausalities = {
      "parameter",   "calculatedParameter", "input", "output", "local",
      "independent", "structuralParameter"};
  static const std::set<std::string> kVariabilities = {"constant", "fixed", "tunable", "discrete",
                                                       "continuous"};
  std::set<std::string> names;
  std::map<std::string, int> vrs;    // per base type in FMI 2.0; one space in FMI 3.0
  std::vector<std::string> outputs;  // FMI 2.0: index; FMI 3.0: value reference
  int index = 0;
  for (const auto& sv : root.child("ModelVariables").children()) {
    if (sv.type() != pugi::node_element) continue;
    ++index;
    // FMI 2.0: ScalarVariable with one type child; FMI 3.0: the type element.
    const pugi::xml_node type_node = v3 ? sv : sv.first_child();
    const std::string tag = type_node.name();
    const std::string name = sv.attribute("name").value();
    const std::string where = "variable '" + name + "' (" + tag + ")";
    if (name.empty()) problem(where, "no name (required)");
    if (!names.insert(name).second) problem(where, "name used twice");
    const auto vr = ParseXsd(sv.attribute("valueReference").value(), Xsd::kUInt);
    if (!vr) problem(where, "valueReference is no xs:unsignedInt");
    const std::string vr_key = (v3 ? "" : tag + ":") + sv.attribute("valueReference").value();
    const std::string causality =
        sv.attribute("causality") ? sv.attribute("causality").value() : "local";
    const std::string variability =
        sv.attribute("variability")
            ? sv.attribute("variability").value()
            : (tag == "Real" || tag == "Float64" || tag == "Float32" ? "continuous" : "discrete");
    if (!kCausalities.count(causality) || (!v3 && causality == "structuralParameter")) {
      problem(where, "causality '" + causality + "'");
    }
    if (!kVariabilities.count(variability)) problem(where, "variability '" + variability + "'");
    const bool real = tag == "Real" || tag == "Float64" || tag == "Float32";
    if (variability == "continuous" && !real) problem(where, "continuous, but not a float type");
    if ((causality == "parameter" || causality == "structuralParameter") &&
        variability != "fixed" && variability != "tunable") {
      problem(where, "a parameter must be fixed or tunable, is " + variability);
    }
    if (causality == "independent" && variability != "continuous") {
      problem(where, "the independent variable must be continuous");
    }
    if (causality == "input" &&
        (variability == "constant" || variability == "fixed" || variability == "tunable")) {
      problem(where, "an input must be discrete or continuous, is " + variability);
    }
    if (vrs[vr_key]++ && (v3 || causality != "output")) {
      // FMI 2.0 allows aliases (one reference, several names); FMI 3.0 none.
      if (v3) problem(where, "valueReference used twice");
    }
    if (causality == "output") {
      outputs.push_back(v3 ? std::string(sv.attribute("valueReference").value())
                           : std::to_string(index));
    }
    if (tag == "Binary" || tag == "String" || tag == "Clock") {
      if ((causality == "parameter" || causality == "input") && !type_node.attribute("start") &&
          !type_node.child("Start")) {
        problem(where, "no start value, required of a " + causality);
      }
      continue;
    }
    const auto& kinds = v3 ? kTypes3 : kTypes2;
    const auto kind = kinds.find(tag);
    if (kind == kinds.end()) {
      problem(where, "unknown type element");
      continue;
    }
    const Xsd xsd = kind->second;
    std::optional<double> min, max, start;
    for (const char* attribute : {"min", "max", "nominal", "start"}) {
      const pugi::xml_attribute a = type_node.attribute(attribute);
      if (!a) continue;
      if (xsd == Xsd::kBool && std::string(attribute) != "start") {
        problem(where, std::string(attribute) + " on a Boolean");
        continue;
      }
      if (std::string(attribute) == "nominal" && !real) {
        problem(where, "nominal on a non-float type");
        continue;
      }
      // An array's start is a list of values.
      std::istringstream items(a.value());
      std::string item;
      int count = 0;
      while (items >> item) {
        ++count;
        const auto x = ParseXsd(item, xsd);
        if (!x) {
          problem(where, std::string(attribute) + "=\"" + a.value() +
                             "\" is outside or no value of " + tag + "'s type");
          continue;
        }
        if (std::string(attribute) == "min") min = x;
        if (std::string(attribute) == "max") max = x;
        if (std::string(attribute) == "start" && count == 1) start = x;
        if (std::string(attribute) == "nominal" && !(*x > 0)) {
          problem(where, "nominal must be > 0, is " + item);
        }
      }
      if (count == 0) problem(where, std::string(attribute) + " is empty");
    }
    if (min && max && *min > *max) problem(where, "min > max");
    if (start && min && *start < *min) problem(where, "start below min");
    if (start && max && *start > *max) problem(where, "start above max");
    const bool has_start = type_node.attribute("start");
    const std::string initial = sv.attribute("initial").value();
    if ((causality == "parameter" || causality == "input" || variability == "constant" ||
         causality == "structuralParameter") &&
        !has_start) {
      problem(where, "no start value, required of a " + causality + " / " + variability);
    }
    if ((causality == "independent" || initial == "calculated") && has_start) {
      problem(where, "a start value, forbidden for " +
                         (causality == "independent" ? std::string("the independent variable")
                                                     : std::string("initial=calculated")));
    }
    for (const char* attribute : {"unit", "displayUnit"}) {
      const std::string unit = type_node.attribute(attribute).value();
      if (!unit.empty() && !units.count(unit)) {
        problem(where, std::string(attribute) + " '" + unit + "' is not in UnitDefinitions");
      }
    }
    const std::string declared = type_node.attribute("declaredType").value();
    if (!declared.empty() && !types.count(declared)) {
      problem(where, "declaredType '" + declared + "' is not in TypeDefinitions");
    }
  }
  // Every output in ModelStructure, once (FMI 2.0 in the order of
  // ModelVariables).
  std::vector<std::string> listed;
  const pugi::xml_node structure = root.child("ModelStructure");
  if (v3) {
    for (const auto& o : structure.children("Output")) {
      listed.push_back(o.attribute("valueReference").value());
    }
    std::multiset<std::string> a(outputs.begin(), outputs.end()), b(listed.begin(), listed.end());
    if (a != b) problem("ModelStructure", "the <Output> elements are not the outputs, once each");
  } else {
    for (const auto& u : structure.child("Outputs").children("Unknown")) {
      listed.push_back(u.attribute("index").value());
    }
    if (listed != outputs) problem("ModelStructure/Outputs", "not every output, in order");
  }
  // Units used in declared types too.
  for (const auto& t : root.child("TypeDefinitions").children()) {
    for (const auto& c : t.children()) {
      const std::string unit = c.attribute("unit").value();
      if (!unit.empty() && !units.count(unit)) {
        problem(std::string("type '") + t.attribute("name").value() + "'",
                "unit '" + unit + "' is not in UnitDefinitions");
      }
    }
    const std::string unit = t.attribute("unit").value();
    if (!unit.empty() && !units.count(unit)) {
      problem(std::string("type '") + t.attribute("name").value() + "'",
              "unit '" + unit + "' is not in UnitDefinitions");
    }
  }
  return problems;
}

}  // namespace linesim::fmu::test
