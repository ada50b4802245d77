#include "sweep/summary.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <locale>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "cosim/files.h"
#include "cosim/variable_table.h"
#include "sweep/results_file.h"

namespace linesim::sweep {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;
using Row = SweepTable::Row;
using Rows = std::vector<const Row*>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// More series than this make a chart unreadable; they are pooled instead.
constexpr std::size_t kMaxSeries = 8;
constexpr std::size_t kMaxFailuresPrinted = 10;

Json Number(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

// A number with 4 significant digits, as printf's %.4g but independent of
// the locale; "-" when not finite.
std::string Sig4(double x) {
  if (!std::isfinite(x)) return "-";
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << std::setprecision(4) << x;
  return out.str();
}

void CheckShape(const SweepTable& t) {
  const auto refuse = [&](const std::string& why) {
    throw std::invalid_argument("sweep table '" + t.name + "': " + why);
  };
  if (t.levels.size() != t.parameters.size()) {
    refuse(std::to_string(t.parameters.size()) + " parameters but " +
           std::to_string(t.levels.size()) + " lists of levels");
  }
  for (const Row& r : t.rows) {
    if (r.values.size() != t.parameters.size() || r.metrics.size() != t.metrics.size()) {
      refuse("run " + std::to_string(r.id) + " has " + std::to_string(r.values.size()) +
             " values and " + std::to_string(r.metrics.size()) + " metrics for " +
             std::to_string(t.parameters.size()) + " parameters and " +
             std::to_string(t.metrics.size()) + " metrics");
    }
  }
}

Rows AllRows(const SweepTable& t) {
  Rows rows;
  for (const Row& r : t.rows) rows.push_back(&r);
  return rows;
}

std::int64_t CountFailed(const Rows& rows) {
  return std::count_if(rows.begin(), rows.end(), [](const Row* r) { return !r->ok; });
}

// Metric `m` of the ok runs among `rows`.
std::vector<double> OkValues(const Rows& rows, std::size_t m) {
  std::vector<double> values;
  for (const Row* r : rows) {
    if (r->ok) values.push_back(r->metrics[m]);
  }
  return values;
}

struct Group {
  std::vector<std::string> values;  // of the grouping parameters
  Rows rows;
};

// `rows` grouped by their values of the parameters `which`, groups in
// first-seen row order.
std::vector<Group> GroupBy(const std::vector<std::size_t>& which, const Rows& rows) {
  std::vector<Group> groups;
  std::map<std::vector<std::string>, std::size_t> index;
  for (const Row* r : rows) {
    std::vector<std::string> key;
    for (std::size_t p : which) key.push_back(r->values[p]);
    const auto [it, added] = index.emplace(key, groups.size());
    if (added) groups.push_back({std::move(key), {}});
    groups[it->second].rows.push_back(r);
  }
  return groups;
}

// `rows` grouped by the value of parameter `p`: one group per level, in
// level order (also levels without runs), then values that are not levels.
std::vector<Group> GroupByLevel(const SweepTable& t, std::size_t p, const Rows& rows) {
  std::vector<Group> groups;
  for (const std::string& level : t.levels[p]) groups.push_back({{level}, {}});
  for (Group& g : GroupBy({p}, rows)) {
    const auto it = std::find_if(groups.begin(), groups.end(),
                                 [&](const Group& known) { return known.values == g.values; });
    if (it != groups.end()) {
      it->rows = std::move(g.rows);
    } else {
      groups.push_back(std::move(g));
    }
  }
  return groups;
}

Json StatsJson(const Stats& s) {
  return {{"n", s.n},
          {"mean", Number(s.mean)},
          {"std", Number(s.std)},
          {"min", Number(s.min)},
          {"max", Number(s.max)}};
}

// "runs", "failed" and the metrics' statistics of a group of runs.
void AddGroupStats(const SweepTable& t, const Rows& rows, Json& group) {
  group["runs"] = rows.size();
  group["failed"] = CountFailed(rows);
  Json metrics = Json::object();
  for (std::size_t m = 0; m < t.metrics.size(); ++m) {
    metrics[t.metrics[m]] = StatsJson(StatsOf(OkValues(rows, m)));
  }
  group["metrics"] = std::move(metrics);
}

Json ValuesJson(const SweepTable& t, const std::vector<std::size_t>& which,
                const std::vector<std::string>& values) {
  Json out = Json::object();
  for (std::size_t i = 0; i < which.size(); ++i) out[t.parameters[which[i]]] = values[i];
  return out;
}

std::vector<std::size_t> AllParameters(const SweepTable& t) {
  std::vector<std::size_t> which(t.parameters.size());
  for (std::size_t p = 0; p < which.size(); ++p) which[p] = p;
  return which;
}

/// A parameter drawn at random: its numeric range over all runs, and its
/// correlation with each metric over the ok runs.
struct RandomParameter {
  double min = kNaN, max = kNaN;
  std::vector<double> correlation;  // per metric
};

RandomParameter DescribeRandom(const SweepTable& t, std::size_t p) {
  RandomParameter out;
  for (const Row& r : t.rows) {
    const auto x = cosim::ParseFiniteValue(r.values[p]);
    if (!x) continue;
    out.min = std::isnan(out.min) ? *x : std::min(out.min, *x);
    out.max = std::isnan(out.max) ? *x : std::max(out.max, *x);
  }
  for (std::size_t m = 0; m < t.metrics.size(); ++m) {
    std::vector<double> xs, ys;
    for (const Row& r : t.rows) {
      const auto x = cosim::ParseFiniteValue(r.values[p]);
      if (!r.ok || !x || !std::isfinite(r.metrics[m])) continue;
      xs.push_back(*x);
      ys.push_back(r.metrics[m]);
    }
    out.correlation.push_back(Correlation(xs, ys));
  }
  return out;
}

// "p=v, q=w" for the parameters `which` and their `values`.
std::string Label(const SweepTable& t, const std::vector<std::size_t>& which,
                  const std::vector<std::string>& values) {
  std::string text;
  for (std::size_t i = 0; i < which.size(); ++i) {
    text += (i ? ", " : "") + t.parameters[which[i]] + "=" + values[i];
  }
  return text;
}

std::string ValuesText(const SweepTable& t, const Row& r) {
  // Repeats of one scenario differ only by their seed.
  if (t.parameters.empty()) return "seed " + std::to_string(r.seed);
  return Label(t, AllParameters(t), r.values);
}

// The runs that the charts against parameter `p` draw as one series each,
// with the series' label: one per combination of the other parameters'
// values (of the listed ones, for a random `p`) while that stays readable,
// otherwise all runs together. The same for every metric.
struct SeriesRows {
  std::string label;
  Rows rows;
};
std::vector<SeriesRows> SeriesOf(const SweepTable& t, std::size_t p, const Rows& all) {
  const bool random = t.levels[p].empty();
  std::vector<std::size_t> others;
  for (std::size_t q = 0; q < t.parameters.size(); ++q) {
    if (q != p && (!random || !t.levels[q].empty())) others.push_back(q);
  }
  if (others.empty() || (!random && !t.grid)) return {{"", all}};
  const std::vector<Group> groups = GroupBy(others, all);
  if (groups.size() > kMaxSeries) {
    return {{random ? "" : "all runs (other parameters pooled)", all}};
  }
  std::vector<SeriesRows> out;
  for (const Group& g : groups) out.push_back({Label(t, others, g.values), g.rows});
  return out;
}

// Columns two spaces apart, padded to their widest cell.
void PrintColumns(const std::vector<std::vector<std::string>>& rows,
                  const std::vector<bool>& right_aligned, std::ostream& out) {
  std::vector<std::size_t> width(right_aligned.size(), 0);
  for (const auto& row : rows) {
    for (std::size_t c = 0; c < row.size(); ++c) width[c] = std::max(width[c], row[c].size());
  }
  for (const auto& row : rows) {
    std::string line = " ";
    for (std::size_t c = 0; c < row.size(); ++c) {
      const std::string pad(width[c] - row[c].size(), ' ');
      line += (c ? "  " : " ") + (right_aligned[c] ? pad + row[c] : row[c] + pad);
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    out << line << "\n";
  }
}

void PrintLevels(const SweepTable& t, std::size_t p, const Rows& all, std::ostream& out) {
  out << "\n" << t.parameters[p] << "\n";
  std::vector<std::vector<std::string>> rows{
      {"value", "runs", "failed", "metric", "mean", "± std", "[min, max]"}};
  for (const Group& g : GroupByLevel(t, p, all)) {
    for (std::size_t m = 0; m < t.metrics.size(); ++m) {
      const Stats s = StatsOf(OkValues(g.rows, m));
      std::vector<std::string> row(7);
      if (m == 0) {
        row[0] = g.values[0];
        row[1] = std::to_string(g.rows.size());
        row[2] = std::to_string(CountFailed(g.rows));
      }
      row[3] = t.metrics[m];
      if (s.n == 0) {
        row[4] = "no ok runs";
      } else {
        row[4] = Sig4(s.mean);
        row[5] = "± " + Sig4(s.std);
        row[6] = "[" + Sig4(s.min) + ", " + Sig4(s.max) + "]";
      }
      rows.push_back(std::move(row));
    }
  }
  PrintColumns(rows, {false, true, true, false, true, false, false}, out);
}

// One line per grid point with each metric's mean over its ok runs: the
// view the marginals above hide (belt speed against compensation, say).
constexpr std::size_t kMaxPointsPrinted = 60;
void PrintPoints(const SweepTable& t, const Rows& all, std::ostream& out) {
  const std::vector<Group> points = GroupBy(AllParameters(t), all);
  if (points.size() > kMaxPointsPrinted) {
    out << "\nper point: " << points.size() << " points, see summary.json (by_point)\n";
    return;
  }
  out << "\nper point (mean over ok runs)\n";
  std::vector<std::vector<std::string>> rows{t.parameters};
  rows[0].push_back("runs");
  rows[0].push_back("failed");
  rows[0].insert(rows[0].end(), t.metrics.begin(), t.metrics.end());
  for (const Group& g : points) {
    std::vector<std::string> row = g.values;
    row.push_back(std::to_string(g.rows.size()));
    row.push_back(std::to_string(CountFailed(g.rows)));
    for (std::size_t m = 0; m < t.metrics.size(); ++m) {
      const Stats st = StatsOf(OkValues(g.rows, m));
      row.push_back(st.n == 0 ? "-" : Sig4(st.mean));
    }
    rows.push_back(std::move(row));
  }
  std::vector<bool> right(rows[0].size(), true);
  for (std::size_t p = 0; p < t.parameters.size(); ++p) right[p] = false;
  PrintColumns(rows, right, out);
}

// Index of metric `name` in t.metrics (the sweep spec checked it is there).
std::size_t MetricIndex(const SweepTable& t, const std::string& name) {
  const auto it = std::find(t.metrics.begin(), t.metrics.end(), name);
  if (it == t.metrics.end()) {
    throw std::invalid_argument("sweep table '" + t.name + "': the reference names metric '" +
                                name + "', which it does not hold");
  }
  return static_cast<std::size_t>(it - t.metrics.begin());
}

// Each metric over all runs (a sweep without parameters): mean ± std
// [min, max], the largest and the mean absolute value.
void PrintOverall(const SweepTable& t, const Rows& all, std::ostream& out) {
  out << "\nover all runs:\n";
  std::vector<std::vector<std::string>> rows{
      {"metric", "n", "mean", "", "[min, max]", "max |x|", "mean |x|"}};
  for (std::size_t m = 0; m < t.metrics.size(); ++m) {
    const Stats s = StatsOf(OkValues(all, m));
    rows.push_back({t.metrics[m], std::to_string(s.n), Sig4(s.mean), "± " + Sig4(s.std),
                    "[" + Sig4(s.min) + ", " + Sig4(s.max) + "]", Sig4(s.max_abs),
                    Sig4(s.mean_abs)});
  }
  PrintColumns(rows, {false, true, true, false, false, true, true}, out);
  std::string constant;
  for (std::size_t m = 0; m < t.metrics.size(); ++m) {
    const Stats s = StatsOf(OkValues(all, m));
    if (s.n > 1 && s.min == s.max) constant += (constant.empty() ? "" : ", ") + t.metrics[m];
  }
  if (!constant.empty()) out << "the same in every run (no histogram): " << constant << "\n";
}

// The reference's table: a row per figure, a column per metric, ours beside
// the source's.
void PrintReference(const SweepTable& t, const Rows& all, std::ostream& out) {
  out << "\n" << t.reference.title << " (this sweep | reference):\n";
  std::vector<std::vector<std::string>> rows{{""}};
  std::vector<std::string> max_row{"maximum absolute error"}, std_row{"standard deviation"},
      mean_row{"mean absolute error"};
  for (const auto& ref : t.reference.metrics) {
    const Stats s = StatsOf(OkValues(all, MetricIndex(t, ref.metric)));
    rows[0].push_back(ref.label);
    max_row.push_back(Sig4(s.max_abs) + " | " + Sig4(ref.max_abs));
    std_row.push_back(Sig4(s.std) + " | " + Sig4(ref.std));
    mean_row.push_back(Sig4(s.mean_abs) + " | " + Sig4(ref.mean_abs));
  }
  rows.push_back(std::move(max_row));
  rows.push_back(std::move(std_row));
  rows.push_back(std::move(mean_row));
  std::vector<bool> right(rows[0].size(), true);
  right[0] = false;
  PrintColumns(rows, right, out);
}

void PrintRandom(const SweepTable& t, std::size_t p, std::ostream& out) {
  const RandomParameter r = DescribeRandom(t, p);
  out << "\n"
      << t.parameters[p] << " (drawn at random): " << Sig4(r.min) << " to " << Sig4(r.max) << "\n";
  std::vector<std::vector<std::string>> rows{{"metric", "correlation over ok runs"}};
  for (std::size_t m = 0; m < t.metrics.size(); ++m) {
    rows.push_back(
        {t.metrics[m], std::isfinite(r.correlation[m]) ? Sig4(r.correlation[m]) : "undefined"});
  }
  PrintColumns(rows, {false, true}, out);
}

// Points of one series: mean, min and max of metric `m` over the ok runs at
// each value of parameter `p`, in level order; values without them left out.
plots::SweepSeries LevelSeries(const SweepTable& t, std::size_t p, std::size_t m, const Rows& rows,
                               std::string label) {
  plots::SweepSeries series{std::move(label), {}, {}, {}, {}};
  for (const Group& g : GroupByLevel(t, p, rows)) {
    const Stats s = StatsOf(OkValues(g.rows, m));
    if (s.n == 0) continue;
    series.x.push_back(g.values[0]);
    series.mean.push_back(s.mean);
    series.min.push_back(s.min);
    series.max.push_back(s.max);
  }
  return series;
}

// Every ok run with a finite metric `m` as a point at its value of `p`.
plots::SweepSeries ScatterSeries(std::size_t p, std::size_t m, const Rows& rows,
                                 std::string label) {
  plots::SweepSeries series;
  series.label = std::move(label);
  for (const Row* row : rows) {
    const Row& r = *row;
    if (!r.ok || !std::isfinite(r.metrics[m])) continue;
    series.x.push_back(r.values[p]);
    series.mean.push_back(r.metrics[m]);
  }
  return series;
}

bool AllNumbers(const std::vector<std::string>& texts) {
  return std::all_of(texts.begin(), texts.end(),
                     [](const std::string& x) { return cosim::ParseFiniteValue(x).has_value(); });
}

// `name`, or with "_2", "_3", ... before ".png" when it is taken.
std::string UniqueFile(const std::string& name, std::set<std::string>& taken) {
  std::string file = name;
  for (int k = 2; !taken.insert(file).second; ++k) {
    file = name.substr(0, name.size() - 4) + "_" + std::to_string(k) + ".png";
  }
  return file;
}

}  // namespace

Stats StatsOf(std::span<const double> values) {
  Stats s;
  double sum = 0.0;
  double sum_abs = 0.0;
  s.min = INFINITY;
  s.max = -INFINITY;
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    ++s.n;
    sum += v;
    sum_abs += std::abs(v);
    s.min = std::min(s.min, v);
    s.max = std::max(s.max, v);
  }
  if (s.n == 0) return {0, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
  s.mean = sum / static_cast<double>(s.n);
  s.mean_abs = sum_abs / static_cast<double>(s.n);
  s.max_abs = std::max(std::abs(s.min), std::abs(s.max));
  // Squares of deviations from the mean (second pass): no cancellation for
  // large values with a small spread.
  double squares = 0.0;
  for (double v : values) {
    if (std::isfinite(v)) squares += (v - s.mean) * (v - s.mean);
  }
  s.std = s.n > 1 ? std::sqrt(squares / static_cast<double>(s.n - 1)) : 0.0;
  return s;
}

double Correlation(std::span<const double> x, std::span<const double> y) {
  const std::size_t n = std::min(x.size(), y.size());
  if (n < 2) return kNaN;
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mx += x[i];
    my += y[i];
  }
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (sxx == 0.0 || syy == 0.0) return kNaN;
  // Rounding can put a perfectly linear relation a hair outside [-1, 1].
  return std::clamp(sxy / std::sqrt(sxx * syy), -1.0, 1.0);
}

nlohmann::ordered_json Summarize(const SweepTable& t) {
  CheckShape(t);
  const Rows all = AllRows(t);
  const std::int64_t failed = CountFailed(all);
  Json s;
  s["name"] = t.name;
  s["runs"] = t.rows.size();
  s["ok"] = static_cast<std::int64_t>(t.rows.size()) - failed;
  s["failed"] = failed;
  s["parameters"] = t.parameters;
  s["metrics"] = t.metrics;
  if (!t.provenance.is_null()) s["provenance"] = t.provenance;

  Json by_parameter = Json::object();
  for (std::size_t p = 0; p < t.parameters.size(); ++p) {
    if (t.levels[p].empty()) {
      const RandomParameter r = DescribeRandom(t, p);
      Json correlation = Json::object();
      for (std::size_t m = 0; m < t.metrics.size(); ++m) {
        correlation[t.metrics[m]] = Number(r.correlation[m]);
      }
      by_parameter[t.parameters[p]] = {
          {"min", Number(r.min)}, {"max", Number(r.max)}, {"correlation", correlation}};
      continue;
    }
    Json groups = Json::array();
    for (const Group& g : GroupByLevel(t, p, all)) {
      Json group = {{"value", g.values[0]}};
      AddGroupStats(t, g.rows, group);
      groups.push_back(std::move(group));
    }
    by_parameter[t.parameters[p]] = std::move(groups);
  }
  s["by_parameter"] = std::move(by_parameter);

  if (t.grid) {
    const std::vector<std::size_t> which = AllParameters(t);
    Json points = Json::array();
    for (const Group& g : GroupBy(which, all)) {
      Json point = {{"values", ValuesJson(t, which, g.values)}};
      AddGroupStats(t, g.rows, point);
      points.push_back(std::move(point));
    }
    s["by_point"] = std::move(points);
  }

  Json failures = Json::array();
  for (const Row& r : t.rows) {
    if (r.ok) continue;
    // The same object as `linesim run`'s summary.json "error".
    const auto text_or_null = [](const std::string& x) { return x.empty() ? Json(nullptr) : Json(x); };
    Json error;
    error["unit"] = text_or_null(r.error_unit);
    error["time_s"] = r.error_time_s ? Json(*r.error_time_s) : Json(nullptr);
    error["phase"] = text_or_null(r.error_phase);
    error["variable"] = text_or_null(r.error_variable);
    error["cause"] = r.error_cause;
    error["message"] = r.error;
    failures.push_back({{"id", r.id},
                        {"seed", r.seed},
                        {"values", ValuesJson(t, AllParameters(t), r.values)},
                        {"error", std::move(error)}});
  }
  s["failures"] = std::move(failures);

  Json overall = Json::object();
  for (std::size_t m = 0; m < t.metrics.size(); ++m) {
    const Stats st = StatsOf(OkValues(all, m));
    Json one = StatsJson(st);
    one["max_abs"] = Number(st.max_abs);
    one["mean_abs"] = Number(st.mean_abs);
    overall[t.metrics[m]] = std::move(one);
  }
  s["overall"] = std::move(overall);
  if (!t.reference.title.empty()) {
    Json metrics = Json::object();
    for (const auto& ref : t.reference.metrics) {
      const Stats st = StatsOf(OkValues(all, MetricIndex(t, ref.metric)));
      metrics[ref.metric] = {
          {"label", ref.label},
          {"ours",
           {{"max_abs", Number(st.max_abs)}, {"std", Number(st.std)},
            {"mean_abs", Number(st.mean_abs)}}},
          {"reference",
           {{"max_abs", Number(ref.max_abs)}, {"std", Number(ref.std)},
            {"mean_abs", Number(ref.mean_abs)}}}};
    }
    s["reference"] = {{"title", t.reference.title}, {"metrics", std::move(metrics)}};
  }
  return s;
}

void PrintSummary(const SweepTable& t, std::ostream& out) {
  CheckShape(t);
  const Rows all = AllRows(t);
  const std::int64_t failed = CountFailed(all);
  out << "sweep " << t.name << ": " << t.rows.size() << " runs, "
      << static_cast<std::int64_t>(t.rows.size()) - failed << " ok, " << failed << " failed\n";
  for (std::size_t p = 0; p < t.parameters.size(); ++p) {
    if (t.levels[p].empty()) {
      PrintRandom(t, p, out);
    } else {
      PrintLevels(t, p, all, out);
    }
  }
  if (t.grid && t.parameters.size() > 1) PrintPoints(t, all, out);
  if (t.parameters.empty()) PrintOverall(t, all, out);
  if (!t.reference.title.empty()) PrintReference(t, all, out);
  if (failed == 0) return;
  out << "\nfailed runs:\n";
  std::size_t printed = 0;
  for (const Row& r : t.rows) {
    if (r.ok) continue;
    if (printed == kMaxFailuresPrinted) break;
    ++printed;
    std::string error = r.error;
    std::replace(error.begin(), error.end(), '\n', ' ');
    out << "  run " << r.id << " (" << ValuesText(t, r) << "): " << error << "\n";
  }
  if (static_cast<std::size_t>(failed) > printed) {
    out << "  and " << static_cast<std::size_t>(failed) - printed << " more\n";
  }
}

std::vector<plots::SweepChart> SweepCharts(const SweepTable& t) {
  CheckShape(t);
  const Rows all = AllRows(t);
  std::vector<std::vector<SeriesRows>> series_rows;
  for (std::size_t p = 0; p < t.parameters.size(); ++p) series_rows.push_back(SeriesOf(t, p, all));
  std::vector<plots::SweepChart> charts;
  std::set<std::string> taken;
  if (t.parameters.empty()) {
    // Repeats of one scenario: how each metric is distributed over them.
    for (std::size_t m = 0; m + 1 < t.metrics.size(); ++m) {
      plots::SweepChart chart;
      chart.histogram = true;
      chart.metric = t.metrics[m];  // its caption and unit come from its name
      chart.run_caption = t.name;
      chart.title = (t.name.empty() ? "" : t.name + ": ") + t.metrics[m] + " over " +
                    std::to_string(t.rows.size()) + " runs";
      chart.x_label = t.metrics[m];
      plots::SweepSeries samples;
      samples.mean = OkValues(all, m);
      const Stats st = StatsOf(samples.mean);
      // A metric the same in every run has no distribution to draw (the
      // summary says its value).
      if (st.n == 0 || st.min == st.max) continue;
      for (const auto& ref : t.reference.metrics) {
        if (ref.metric != t.metrics[m]) continue;
        chart.reference = {t.reference.title, ref.max_abs, ref.std, ref.mean_abs};
        chart.x_label = ref.label;
      }
      chart.series.push_back(std::move(samples));
      chart.file = UniqueFile(plots::SafeFileName(t.metrics[m] + "_histogram.png"), taken);
      charts.push_back(std::move(chart));
    }
    return charts;
  }
  for (std::size_t m = 0; m < t.metrics.size(); ++m) {
    for (std::size_t p = 0; p < t.parameters.size(); ++p) {
      const std::string& path = t.parameters[p];
      plots::SweepChart chart;
      chart.title = (t.name.empty() ? "" : t.name + ": ") + t.metrics[m] + " against " + path;
      chart.metric = t.metrics[m];
      chart.run_caption = t.name;
      chart.x_label = path;
      chart.y_label = t.metrics[m];
      std::vector<plots::SweepSeries> series;
      if (t.levels[p].empty()) {
        chart.scatter = true;
        for (const SeriesRows& g : series_rows[p]) {
          series.push_back(ScatterSeries(p, m, g.rows, g.label));
        }
        std::vector<std::string> xs;
        for (const auto& one : series) xs.insert(xs.end(), one.x.begin(), one.x.end());
        chart.categorical_x = !AllNumbers(xs);
      } else {
        chart.categorical_x = !AllNumbers(t.levels[p]);
        chart.categories = t.levels[p];
        for (const SeriesRows& g : series_rows[p]) {
          series.push_back(LevelSeries(t, p, m, g.rows, g.label));
        }
      }
      for (auto& s : series) {
        if (!s.x.empty()) chart.series.push_back(std::move(s));
      }
      if (chart.series.empty()) continue;
      chart.file = UniqueFile(plots::SafeFileName(t.metrics[m] + "_vs_" + path + ".png"), taken);
      charts.push_back(std::move(chart));
    }
  }
  return charts;
}

std::vector<std::string> WriteReferenceTable(const std::string& dir, const SweepTable& t) {
  if (t.reference.title.empty()) return {};
  const Rows all = AllRows(t);
  std::vector<Stats> ours;
  for (const auto& ref : t.reference.metrics) ours.push_back(StatsOf(OkValues(all, MetricIndex(t, ref.metric))));
  const auto num = [](double x) { return std::isfinite(x) ? cosim::FormatValue(x) : std::string(); };
  std::string csv = "metric,label,figure,ours,reference\n";
  for (std::size_t i = 0; i < ours.size(); ++i) {
    const auto& ref = t.reference.metrics[i];
    const Stats& s = ours[i];
    std::string head = JoinCsvLine({ref.metric, ref.label});  // ends in a newline
    head.back() = ',';
    csv += head + "max_abs," + num(s.max_abs) + "," + num(ref.max_abs) + "\n";
    csv += head + "std," + num(s.std) + "," + num(ref.std) + "\n";
    csv += head + "mean_abs," + num(s.mean_abs) + "," + num(ref.mean_abs) + "\n";
    csv += head + "mean," + num(s.mean) + ",\n";
    csv += head + "min," + num(s.min) + ",\n";
    csv += head + "max," + num(s.max) + ",\n";
    csv += head + "runs," + std::to_string(s.n) + ",\n";
  }
  // Markdown: the source's layout (a row per figure), two columns per
  // metric (ours, the reference's); then what makes each metric.
  const auto ref_cell = [](double v) { return std::isfinite(v) ? Sig4(v) : std::string("-"); };
  std::string md = "# " + t.reference.title + "\n\nOurs: " + t.name + ", " +
                   std::to_string(all.size()) + " runs (" +
                   std::to_string(static_cast<std::int64_t>(all.size()) - CountFailed(all)) +
                   " ok).\n\n|  |";
  std::string rule = "|---|", max_row = "| maximum absolute error |", std_row = "| standard deviation |",
              mean_row = "| mean absolute error |", dist_row = "| mean [min, max] |";
  for (std::size_t i = 0; i < ours.size(); ++i) {
    const auto& ref = t.reference.metrics[i];
    const Stats& s = ours[i];
    md += " " + ref.label + ", ours | " + ref.label + ", reference |";
    rule += "---|---|";
    max_row += " " + Sig4(s.max_abs) + " | " + ref_cell(ref.max_abs) + " |";
    std_row += " " + Sig4(s.std) + " | " + ref_cell(ref.std) + " |";
    mean_row += " " + Sig4(s.mean_abs) + " | " + ref_cell(ref.mean_abs) + " |";
    dist_row += " " + Sig4(s.mean) + " [" + Sig4(s.min) + ", " + Sig4(s.max) + "] | - |";
  }
  md += "\n" + rule + "\n" + max_row + "\n" + std_row + "\n" + mean_row + "\n" + dist_row + "\n";
  bool notes = false;
  for (const auto& ref : t.reference.metrics) notes = notes || !ref.note.empty();
  if (notes) {
    md += "\nWhat makes each column in the simulation:\n\n";
    for (const auto& ref : t.reference.metrics) {
      if (!ref.note.empty()) md += "- " + ref.label + ": " + ref.note + "\n";
    }
  }
  fs::create_directories(dir);
  const fs::path base = fs::path(dir) / t.reference.file;
  cosim::WriteFileAtomically(base.string() + ".csv", csv);
  cosim::WriteFileAtomically(base.string() + ".md", md);
  return {base.string() + ".csv", base.string() + ".md"};
}

std::vector<std::string> WriteSweepReport(const std::string& dir, const SweepTable& t) {
  Json summary = Summarize(t);
  fs::create_directories(dir);
  const fs::path summary_path = fs::path(dir) / "summary.json";
  std::vector<std::string> written{summary_path.string()};
  const std::vector<std::string> tables = WriteReferenceTable(dir, t);
  // The numbers matter more than the pictures: a plot failure is recorded,
  // not thrown.
  try {
    Json files = Json::array();
    for (const std::string& png : plots::WriteSweepPlots(dir, SweepCharts(t))) {
      files.push_back(fs::path(png).filename().string());
      written.push_back(png);
    }
    summary["plots"] = {{"files", std::move(files)}};
  } catch (const std::runtime_error& e) {
    written.resize(1);
    summary["plots"] = {{"error", e.what()}};
  }
  // Run errors and gnuplot's text may hold bytes that are not UTF-8.
  cosim::WriteFileAtomically(summary_path.string(),
                             summary.dump(2, ' ', false, Json::error_handler_t::replace) + "\n");
  written.insert(written.begin() + 1, tables.begin(), tables.end());
  return written;
}

}  // namespace linesim::sweep
