#include "fmu_export/model_description_writer.h"

#include <algorithm>
#include <cstdint>
#include <map>
#include <set>
#include <sstream>

#include "units/fmu/model_description.h"

namespace linesim::fmu_export {

namespace {

std::string Escape(const std::string& s) {
  std::string out;
  out.reserve(s.size());
  for (const char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\n':
        out += "&#10;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

const char* Causality(const cosim::VariableInfo& info) {
  switch (info.causality) {
    case cosim::Causality::kParameter:
      // FMI 2.0 has no constant parameter: a constant is a local.
      return info.variability == cosim::Variability::kConstant ? "local" : "parameter";
    case cosim::Causality::kInput:
      return "input";
    case cosim::Causality::kOutput:
      return "output";
    case cosim::Causality::kLocal:
      return "local";
  }
  return "local";
}

const char* Variability(const cosim::VariableInfo& info, cosim::VarType scalar_type) {
  switch (info.variability) {
    case cosim::Variability::kConstant:
      return "constant";
    case cosim::Variability::kFixed:
      return "fixed";
    case cosim::Variability::kTunable:
      return "tunable";
    case cosim::Variability::kDiscrete:
      return "discrete";
    case cosim::Variability::kContinuous:
      // FMI 2.0: only a Real may be continuous.
      return scalar_type == cosim::VarType::kReal ? "continuous" : "discrete";
  }
  return "continuous";
}

// The start value of one scalar as FMI text: the value the unit holds now
// (its default, the model file's, or --set's), which the FMU's unit gets.
std::string StartText(const cosim::VariableTable& table, const ExportedVariable& v) {
  const cosim::Value value = table.GetValue(v.ref);
  if (v.is_element) return cosim::FormatValue(std::get<std::vector<double>>(value).at(v.element));
  if (const auto* d = std::get_if<double>(&value)) return cosim::FormatValue(*d);
  if (const auto* i = std::get_if<std::int64_t>(&value)) return std::to_string(*i);
  if (const auto* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
  if (const auto* s = std::get_if<std::string>(&value)) return *s;
  return "";
}

const char* TypeElement(cosim::VarType t) {
  switch (t) {
    case cosim::VarType::kInteger:
      return "Integer";
    case cosim::VarType::kBoolean:
      return "Boolean";
    case cosim::VarType::kString:
      return "String";
    default:
      return "Real";
  }
}

// UnitDefinitions: each unit with its SI base units (FMI 2.0 and 3.0 alike).
void WriteUnits(std::ostringstream& x, const std::set<std::string>& units) {
  if (units.empty()) return;
  static const char* kNames[8] = {"kg", "m", "s", "A", "K", "mol", "cd", "rad"};
  x << "  <UnitDefinitions>\n";
  for (const auto& u : units) {
    x << "    <Unit name=\"" << Escape(u) << "\"";
    const auto exps = fmu::SiExponents(u);
    if (!exps) {
      x << "/>\n";
      continue;
    }
    x << ">\n      <BaseUnit";
    for (int i = 0; i < 8; ++i) {
      if ((*exps)[static_cast<std::size_t>(i)] != 0) {
        x << " " << kNames[i] << "=\"" << (*exps)[static_cast<std::size_t>(i)] << "\"";
      }
    }
    x << "/>\n    </Unit>\n";
  }
  x << "  </UnitDefinitions>\n";
}

}  // namespace

std::string WriteModelDescription(const cosim::Unit& unit, const Layout& layout,
                                  const DescriptionInfo& d) {
  const cosim::VariableTable& table = unit.variables();
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x << "<fmiModelDescription fmiVersion=\"2.0\" modelName=\"" << Escape(d.model_name)
    << "\" guid=\"" << d.guid << "\" description=\"" << Escape(d.description)
    << "\" generationTool=\"linesim export-fmu\" variableNamingConvention=\"structured\""
       " numberOfEventIndicators=\"0\">\n";
  x << "  <CoSimulation modelIdentifier=\"" << d.model_identifier
    << "\" needsExecutionTool=\"false\" canHandleVariableCommunicationStepSize=\"true\""
       " canInterpolateInputs=\"false\" maxOutputDerivativeOrder=\"0\""
       " canRunAsynchronuously=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\""
       " canNotUseMemoryManagementFunctions=\"true\" canGetAndSetFMUstate=\"true\""
       " canSerializeFMUstate=\"true\" providesDirectionalDerivative=\"false\"/>\n";

  std::set<std::string> units;
  for (const auto& v : layout.variables) {
    const auto& info = table.info(v.ref);
    if (v.type == cosim::VarType::kReal && !info.unit.empty() && info.unit != "1") {
      units.insert(info.unit);
    }
  }
  WriteUnits(x, units);
  x << "  <DefaultExperiment startTime=\"0\" stepSize=\"0.001\"/>\n";

  x << "  <ModelVariables>\n";
  std::vector<std::uint32_t> outputs;
  for (std::uint32_t vr = 0; vr < layout.variables.size(); ++vr) {
    const ExportedVariable& v = layout.variables[vr];
    const cosim::VariableInfo& info = table.info(v.ref);
    const char* causality = Causality(info);
    const bool has_start = info.causality == cosim::Causality::kParameter ||
                           info.causality == cosim::Causality::kInput;
    if (info.causality == cosim::Causality::kOutput) outputs.push_back(vr);
    x << "    <!-- index " << vr + 1 << " -->\n";
    x << "    <ScalarVariable name=\"" << Escape(v.name) << "\" valueReference=\"" << vr
      << "\" causality=\"" << causality << "\" variability=\"" << Variability(info, v.type) << "\"";
    if (has_start && info.causality == cosim::Causality::kParameter) x << " initial=\"exact\"";
    if (!info.description.empty()) x << " description=\"" << Escape(info.description) << "\"";
    x << ">\n      <" << TypeElement(v.type);
    if (v.type == cosim::VarType::kReal) {
      if (!info.unit.empty() && info.unit != "1") x << " unit=\"" << Escape(info.unit) << "\"";
      if (const auto lo = info.rule.lower()) x << " min=\"" << cosim::FormatValue(*lo) << "\"";
      if (const auto hi = info.rule.upper()) x << " max=\"" << cosim::FormatValue(*hi) << "\"";
    } else if (v.type == cosim::VarType::kInteger) {
      // FMI 2.0's Integer has 32 bits (fmi2Integer, xs:int): a wider
      // declared range is clipped to it, since no value beyond can pass
      // fmi2SetInteger (a device seed up to 2^32 - 1 reaches 2^31 - 1 here,
      // all of it in FMI 3.0's Int64).
      if (const auto lo = info.rule.lower(); lo && *lo > INT32_MIN) {
        x << " min=\"" << static_cast<long long>(*lo) << "\"";
      }
      if (const auto hi = info.rule.upper()) {
        x << " max=\"" << static_cast<long long>(std::min<double>(*hi, INT32_MAX)) << "\"";
      }
    }
    if (has_start) x << " start=\"" << Escape(StartText(table, v)) << "\"";
    x << "/>\n    </ScalarVariable>\n";
  }
  x << "  </ModelVariables>\n";

  x << "  <ModelStructure>\n";
  if (!outputs.empty()) {
    x << "    <Outputs>\n";
    for (std::uint32_t vr : outputs) {
      const cosim::VariableInfo& info = table.info(layout.variables[vr].ref);
      x << "      <Unknown index=\"" << vr + 1 << "\" dependencies=\"";
      std::set<std::uint32_t> indices;  // ascending
      for (cosim::ValueRef in : info.depends_on) {
        const auto& in_info = table.info(in);
        const std::size_t n = in_info.type == cosim::VarType::kRealArray ? in_info.size : 1;
        for (std::size_t i = 0; i < n; ++i) {
          indices.insert(layout.first_vr[in] + static_cast<std::uint32_t>(i) + 1);
        }
      }
      bool first = true;
      for (std::uint32_t index : indices) {
        x << (first ? "" : " ") << index;
        first = false;
      }
      x << "\"/>\n";
    }
    x << "    </Outputs>\n    <InitialUnknowns>\n";
    for (std::uint32_t vr : outputs) x << "      <Unknown index=\"" << vr + 1 << "\"/>\n";
    x << "    </InitialUnknowns>\n";
  }
  x << "  </ModelStructure>\n";
  x << "</fmiModelDescription>\n";
  return x.str();
}

std::string WriteModelDescription3(const cosim::Unit& unit, const DescriptionInfo& d) {
  const cosim::VariableTable& table = unit.variables();
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  x << "<fmiModelDescription fmiVersion=\"3.0\" modelName=\"" << Escape(d.model_name)
    << "\" instantiationToken=\"" << d.guid << "\" description=\"" << Escape(d.description)
    << "\" generationTool=\"linesim export-fmu\" variableNamingConvention=\"structured\">\n";
  x << "  <CoSimulation modelIdentifier=\"" << d.model_identifier
    << "\" needsExecutionTool=\"false\" canBeInstantiatedOnlyOncePerProcess=\"false\""
       " canGetAndSetFMUState=\"true\" canSerializeFMUState=\"true\""
       " providesDirectionalDerivatives=\"false\" providesAdjointDerivatives=\"false\""
       " providesPerElementDependencies=\"false\" canHandleVariableCommunicationStepSize=\"true\""
       " maxOutputDerivativeOrder=\"0\" providesIntermediateUpdate=\"false\""
       " mightReturnEarlyFromDoStep=\"false\" canReturnEarlyAfterIntermediateUpdate=\"false\""
       " hasEventMode=\"false\" providesEvaluateDiscreteStates=\"false\"/>\n";
  std::set<std::string> units;
  for (const auto& info : table.infos()) {
    if ((info.type == cosim::VarType::kReal || info.type == cosim::VarType::kRealArray) &&
        !info.unit.empty() && info.unit != "1") {
      units.insert(info.unit);
    }
  }
  WriteUnits(x, units);
  x << "  <DefaultExperiment startTime=\"0\" stepSize=\"0.001\"/>\n";

  x << "  <ModelVariables>\n";
  std::vector<cosim::ValueRef> outputs;
  for (const auto& info : table.infos()) {
    const bool real = info.type == cosim::VarType::kReal || info.type == cosim::VarType::kRealArray;
    const char* tag = real                                    ? "Float64"
                      : IsInt64In3(info)                      ? "Int64"
                      : info.type == cosim::VarType::kInteger ? "Int32"
                      : info.type == cosim::VarType::kBoolean ? "Boolean"
                                                              : "String";
    const cosim::VarType scalar = real ? cosim::VarType::kReal : info.type;
    const bool has_start = info.causality == cosim::Causality::kParameter ||
                           info.causality == cosim::Causality::kInput;
    if (info.causality == cosim::Causality::kOutput) outputs.push_back(info.ref);
    x << "    <" << tag << " name=\"" << Escape(info.name) << "\" valueReference=\"" << info.ref
      << "\" causality=\"" << Causality(info) << "\" variability=\"" << Variability(info, scalar)
      << "\"";
    if (!info.description.empty()) x << " description=\"" << Escape(info.description) << "\"";
    if (real) {
      if (!info.unit.empty() && info.unit != "1") x << " unit=\"" << Escape(info.unit) << "\"";
      if (const auto lo = info.rule.lower()) x << " min=\"" << cosim::FormatValue(*lo) << "\"";
      if (const auto hi = info.rule.upper()) x << " max=\"" << cosim::FormatValue(*hi) << "\"";
    } else if (info.type == cosim::VarType::kInteger) {
      if (const auto lo = info.rule.lower()) x << " min=\"" << static_cast<long long>(*lo) << "\"";
      if (const auto hi = info.rule.upper()) x << " max=\"" << static_cast<long long>(*hi) << "\"";
    }
    const cosim::Value value = table.GetValue(info.ref);
    std::string start;
    if (has_start && info.type != cosim::VarType::kString) {
      if (const auto* a = std::get_if<std::vector<double>>(&value)) {
        for (std::size_t i = 0; i < a->size(); ++i) {
          start += (i ? " " : "") + cosim::FormatValue((*a)[i]);
        }
      } else if (const auto* r = std::get_if<double>(&value)) {
        start = cosim::FormatValue(*r);
      } else if (const auto* n = std::get_if<std::int64_t>(&value)) {
        start = std::to_string(*n);
      } else if (const auto* b = std::get_if<bool>(&value)) {
        start = *b ? "true" : "false";
      }
      x << " start=\"" << start << "\"";
    }
    const bool children = info.type == cosim::VarType::kRealArray ||
                          (has_start && info.type == cosim::VarType::kString);
    if (!children) {
      x << "/>\n";
      continue;
    }
    x << ">\n";
    if (info.type == cosim::VarType::kRealArray) {
      x << "      <Dimension start=\"" << info.size << "\"/>\n";
    } else {
      x << "      <Start value=\"" << Escape(std::get<std::string>(value)) << "\"/>\n";
    }
    x << "    </" << tag << ">\n";
  }
  x << "  </ModelVariables>\n";

  x << "  <ModelStructure>\n";
  for (cosim::ValueRef out : outputs) {
    std::set<cosim::ValueRef> deps(table.info(out).depends_on.begin(),
                                   table.info(out).depends_on.end());
    x << "    <Output valueReference=\"" << out << "\" dependencies=\"";
    bool first = true;
    for (cosim::ValueRef in : deps) {
      x << (first ? "" : " ") << in;
      first = false;
    }
    x << "\"/>\n";
  }
  for (cosim::ValueRef out : outputs)
    x << "    <InitialUnknown valueReference=\"" << out << "\"/>\n";
  x << "  </ModelStructure>\n";
  x << "</fmiModelDescription>\n";
  return x.str();
}

}  // namespace linesim::fmu_export
