#include "cosim/observers.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "cosim/closest_names.h"

namespace linesim::cosim {

std::vector<Probe> ResolveProbes(const System& system, const std::vector<std::string>& names) {
  std::vector<Probe> probes;
  std::vector<Problem> problems;
  const auto add = [&](const std::string& label, System::Resolved r) {
    const VariableInfo& info = system.unit(r.unit).variables().info(r.ref);
    if (info.type == VarType::kString) {
      problems.push_back({"cannot record '" + label + "': strings are not numbers", std::nullopt});
      return;
    }
    if (info.type == VarType::kRealArray && r.index < 0) {
      for (std::size_t i = 0; i < info.size; ++i) {
        probes.push_back({label + "[" + std::to_string(i) + "]",
                          {r.unit, r.ref, static_cast<std::ptrdiff_t>(i)},
                          VarType::kReal});
      }
      return;
    }
    probes.push_back({label, r, info.type == VarType::kRealArray ? VarType::kReal : info.type});
  };
  for (const std::string& name : names) {
    const auto star = name.size() > 2 ? name.rfind(".*") : std::string::npos;
    if (star != std::string::npos && star == name.size() - 2) {
      const std::string unit_name = name.substr(0, star);
      const auto u = system.FindUnit(unit_name);
      if (!u) {
        problems.push_back({"unknown unit '" + unit_name + "' in '" + name + "'" +
                                ClosestHint(unit_name, system.UnitNames()),
                            std::nullopt});
        continue;
      }
      for (const auto& info : system.unit(*u).variables().infos()) {
        if (info.causality == Causality::kOutput && info.type != VarType::kString) {
          add(unit_name + "." + info.name, {*u, info.ref, -1});
        }
      }
      continue;
    }
    try {
      add(name, system.Resolve(name));
    } catch (const ConfigError& e) {
      for (const auto& p : e.problems()) problems.push_back(p);
    }
  }
  if (!problems.empty()) throw ConfigError(std::move(problems));
  return probes;
}

double ReadProbe(const System& system, const Probe& p) {
  const VariableTable& t = system.unit(p.where.unit).variables();
  if (p.where.index >= 0) return t.GetRealElement(p.where.ref, p.where.index);
  switch (p.type) {
    case VarType::kInteger:
      return static_cast<double>(t.GetInteger(p.where.ref));
    case VarType::kBoolean:
      return t.GetBoolean(p.where.ref) ? 1.0 : 0.0;
    default:
      return t.GetReal(p.where.ref);
  }
}

CsvRecorder::CsvRecorder(std::ostream& out, std::vector<Probe> probes, TimeNs interval)
    : out_(out), probes_(std::move(probes)), interval_(interval) {}

void CsvRecorder::OnStart(const Master& master) {
  start_ = master.options().start;
  if (interval_ <= 0) interval_ = master.options().base_step;
  // Rows exist only at master steps: any other interval would record nothing.
  if (interval_ % master.options().base_step != 0) {
    throw std::invalid_argument("recording interval " + FormatSeconds(interval_) +
                                " s is not a multiple of the master step " +
                                FormatSeconds(master.options().base_step) + " s");
  }
  out_ << "time";
  for (const Probe& p : probes_) out_ << ',' << p.label;
  out_ << '\n';
  out_.flush();
}

void CsvRecorder::OnSample(TimeNs t, const System& system) {
  if ((t - start_) % interval_ != 0) return;
  line_ = FormatSeconds(t);
  char buf[32];
  for (const Probe& p : probes_) {
    line_ += ',';
    // Shortest representation that reads back to the same double.
    const auto res = std::to_chars(buf, buf + sizeof buf, ReadProbe(system, p));
    line_.append(buf, res.ptr);
  }
  line_ += '\n';
  out_ << line_;
  // Small batches keep the cost of flushing low while a killed process
  // loses at most a few rows.
  if (++rows_ % 64 == 0) out_.flush();
}

void CsvRecorder::OnEnd(TimeNs, bool) { out_.flush(); }

bool ParseReduction(const std::string& text, Reduction* out) {
  static const std::pair<const char*, Reduction> kNames[] = {
      {"final", Reduction::kFinal},    {"min", Reduction::kMin},   {"max", Reduction::kMax},
      {"max_abs", Reduction::kMaxAbs}, {"mean", Reduction::kMean}, {"rms", Reduction::kRms}};
  for (const auto& [name, r] : kNames) {
    if (text == name) {
      *out = r;
      return true;
    }
  }
  return false;
}

std::string ToString(Reduction reduction) {
  const auto names = ReductionNames();
  return names[static_cast<std::size_t>(reduction)];
}

std::vector<std::string> ReductionNames() {
  return {"final", "min", "max", "max_abs", "mean", "rms"};
}

MetricsObserver::MetricsObserver(std::vector<MetricSpec> specs)
    : specs_(std::move(specs)), acc_(specs_.size()) {}

void MetricsObserver::OnSample(TimeNs, const System& system) {
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const double v = ReadProbe(system, specs_[i].probe);
    Accumulator& a = acc_[i];
    if (samples_ == 0) {
      a.min = a.max = v;
    } else {
      a.min = std::min(a.min, v);
      a.max = std::max(a.max, v);
    }
    a.last = v;
    a.max_abs = std::max(a.max_abs, std::abs(v));
    a.sum += v;
    a.sum_sq += v * v;
  }
  ++samples_;
}

std::vector<std::string> MetricsObserver::NonFiniteResults() const {
  std::vector<std::string> out;
  for (const auto& [name, value] : Results()) {
    if (std::isfinite(value)) continue;
    out.push_back("metric '" + name + "' is " + (std::isnan(value) ? "NaN" : "infinite") +
                  (samples_ == 0 ? " (no sample was taken)"
                                 : " (its reduction overflowed): the run's numbers are not "
                                   "trustworthy"));
  }
  return out;
}

std::vector<RunError> MetricsObserver::NonFiniteErrors(TimeNs end) const {
  std::vector<RunError> out;
  const auto texts = NonFiniteResults();
  std::size_t k = 0;
  for (const auto& [name, value] : Results()) {
    if (std::isfinite(value)) continue;
    RunError e = MakeRunError(std::nullopt, RunPhase::kMetric, "", texts[k++], name);
    e.message = e.cause;  // the text names the metric already
    e.time = end;
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<std::pair<std::string, double>> MetricsObserver::Results() const {
  std::vector<std::pair<std::string, double>> out;
  const double n = static_cast<double>(samples_);
  for (std::size_t i = 0; i < specs_.size(); ++i) {
    const Accumulator& a = acc_[i];
    double v = std::numeric_limits<double>::quiet_NaN();
    if (samples_ > 0) {
      switch (specs_[i].reduction) {
        case Reduction::kFinal:
          v = a.last;
          break;
        case Reduction::kMin:
          v = a.min;
          break;
        case Reduction::kMax:
          v = a.max;
          break;
        case Reduction::kMaxAbs:
          v = a.max_abs;
          break;
        case Reduction::kMean:
          v = a.sum / n;
          break;
        case Reduction::kRms:
          v = std::sqrt(a.sum_sq / n);
          break;
      }
    }
    out.emplace_back(specs_[i].name, v);
  }
  return out;
}

}  // namespace linesim::cosim
