#include "sweep/results_file.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "config/input_files.h"
#include "cosim/files.h"
#include "cosim/variable_table.h"
#include "platform/sha256.h"

namespace linesim::sweep {

namespace {

std::string Quote(const std::string& field) {
  const bool plain = field.find_first_of(",\"\n\r") == std::string::npos &&
                     (field.empty() || (field.front() != ' ' && field.back() != ' '));
  if (plain) return field;
  std::string out = "\"";
  for (char c : field) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

std::string Number(double v) { return std::isfinite(v) ? cosim::FormatValue(v) : ""; }

std::uint64_t Fnv1a(std::uint64_t h, std::string_view text) {
  for (char c : text) {
    h ^= static_cast<unsigned char>(c);
    h *= 1099511628211ull;
  }
  return h;
}

// The row's check (results.csv's last column): FNV-1a 64, as 16 hex
// digits, of the row's fields before wall_s (run id, the plan's values and
// seed, metrics, status, errors) joined as results.csv writes them. Wall
// time is left out: it is the one field that differs between two runs of a
// sweep, and the check is the same bytes with it. Resume recomputes it, so
// a row changed by accident (a hand edit, a spreadsheet's re-save, a line
// cut or merged) is done again rather than parsed into the results. It
// catches accidents, not forgery: whoever can edit the file can recompute
// it (docs/outputs.md says why no key is kept).
std::string RowCheck(std::string_view proven_text) {
  const std::uint64_t h = Fnv1a(1469598103934665603ull, proven_text);
  char hex[17];
  static const char* kDigits = "0123456789abcdef";
  for (int i = 0; i < 16; ++i) hex[i] = kDigits[(h >> (60 - 4 * i)) & 0xf];
  hex[16] = '\0';
  return hex;
}

// A missing file reads as empty: the fingerprint then differs from any
// file's, and Resume finds no header.
std::string ReadWhole(const std::string& path) { return cosim::ReadWholeFile(path).value_or(""); }

std::FILE* OpenOrThrow(const std::string& path, const char* mode) {
  std::FILE* f = std::fopen(path.c_str(), mode);
  if (!f) throw std::runtime_error("cannot write " + path + ": " + std::strerror(errno));
  return f;
}

std::optional<std::int64_t> ParseId(const std::string& text) {
  std::int64_t id = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), id);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return id;
}

double ParseNumber(const std::string& text) {
  return cosim::ParseFiniteValue(text).value_or(std::numeric_limits<double>::quiet_NaN());
}

// Whether a results row (split, with every column) is what run `run` of the
// plan writes: its values and seed as planned, a known status, and numbers
// where numbers belong (an ok run's metrics are all finite: a run with a
// non-finite metric fails).
// Columns after the metrics: status, error, the error fields, wall_s.
constexpr std::size_t kErrorFields = 5;  // unit, time_s, phase, variable, cause
std::size_t StatusColumn(std::size_t np, std::size_t nm) { return 2 + np + nm; }
std::size_t WallColumn(std::size_t np, std::size_t nm) { return 4 + np + nm + kErrorFields; }

bool RowMatchesPlan(const SweepSpec& spec, const RunSpec& run, const std::vector<std::string>& f) {
  const std::size_t np = spec.parameters.size(), nm = spec.metrics.size();
  for (std::size_t i = 0; i < np; ++i) {
    if (f[1 + i] != run.values[i]) return false;
  }
  if (f[1 + np] != std::to_string(run.seed)) return false;
  const std::string& status = f[2 + np + nm];
  if (status != "ok" && status != "failed") return false;
  for (std::size_t m = 0; m < nm; ++m) {
    const std::string& text = f[2 + np + m];
    if (text.empty() && status == "failed") continue;
    if (!cosim::ParseFiniteValue(text)) return false;
  }
  return cosim::ParseFiniteValue(f[WallColumn(np, nm)]).has_value();
}

}  // namespace

std::vector<std::string> ResultsHeader(const SweepSpec& spec) {
  std::vector<std::string> h{"run_id"};
  for (const auto& p : spec.parameters) h.push_back(p.path);
  h.push_back("seed");
  for (const auto& m : spec.metrics) h.push_back(m);
  h.insert(h.end(), {"status", "error", "error_unit", "error_time_s", "error_phase",
                     "error_variable", "error_cause", "wall_s", "row_check"});
  return h;
}

std::string JoinCsvLine(const std::vector<std::string>& fields) {
  std::string line;
  for (std::size_t i = 0; i < fields.size(); ++i) line += (i ? "," : "") + Quote(fields[i]);
  return line + "\n";
}

std::optional<std::vector<std::string>> SplitCsvLine(std::string_view line) {
  std::vector<std::string> fields(1);
  bool quoted = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        fields.back() += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        fields.back() += c;
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields.emplace_back();
    } else {
      fields.back() += c;
    }
  }
  if (quoted) return std::nullopt;
  return fields;
}

std::string FormatRow(const RunSpec& run, const RunOutcome& outcome) {
  std::vector<std::string> f{std::to_string(run.id)};
  f.insert(f.end(), run.values.begin(), run.values.end());
  f.push_back(std::to_string(outcome.seed));
  for (double m : outcome.metrics) f.push_back(Number(m));
  f.push_back(outcome.status == RunStatus::kOk ? "ok" : "failed");
  f.push_back(outcome.error);
  const bool failed = outcome.status != RunStatus::kOk;
  const cosim::RunError& e = outcome.failure;
  f.push_back(failed ? e.unit : "");
  f.push_back(failed && e.time ? cosim::FormatValue(cosim::NsToSeconds(*e.time)) : "");
  f.push_back(failed ? std::string(cosim::ToString(e.phase)) : "");
  f.push_back(failed ? e.variable : "");
  f.push_back(failed ? e.cause : "");
  const std::string proven = JoinCsvLine(f);
  f.push_back(cosim::FormatValue(outcome.wall_s));
  f.push_back(RowCheck(std::string_view(proven).substr(0, proven.size() - 1)));
  return JoinCsvLine(f);
}

std::string SweepFingerprint(const SweepSpec& spec) {
  std::string text;
  const auto add = [&text](std::string_view line) {
    text += line;
    text += '\n';
  };
  // The files the runs are built from, by content: every file the base
  // scenario's loads read (config/input_files.h), whatever its kind and
  // wherever it lies.
  for (const auto& [path, digest] : spec.inputs) add("file " + path + " " + digest);
  // What decides each run's overrides, seed and columns.
  for (const auto& a : FixedOverrides(spec)) add("set " + a);
  for (const auto& p : spec.parameters) {
    add("parameter " + p.path + " kind " + std::to_string(static_cast<int>(p.kind)));
    for (const auto& v : p.values) add(v);
    add("distribution " + std::to_string(static_cast<int>(p.distribution)) + " " +
        cosim::FormatValue(p.a) + " " + cosim::FormatValue(p.b));
  }
  add("combination " + std::to_string(static_cast<int>(spec.combination)) + " samples " +
      std::to_string(spec.samples) + " repeats " + std::to_string(spec.repeats) + " seed " +
      std::to_string(spec.seed) + " seeds " + std::to_string(static_cast<int>(spec.seeds)));
  for (const auto& m : spec.metrics) add("metric " + m);
  return platform::Sha256Hex(text);
}

void WriteSweepIdentity(const std::string& path, const SweepSpec& spec,
                        const std::string& fingerprint,
                        const std::map<std::string, std::string>& inputs) {
  nlohmann::ordered_json id;
  id["name"] = spec.name;
  id["sweep_file"] = spec.file;
  id["scenario"] = spec.scenario;
  id["runs"] = RunCount(spec);
  id["fingerprint"] = fingerprint;
  id["inputs"] = nlohmann::ordered_json::object();
  for (const auto& [file, digest] : inputs) id["inputs"][file] = digest;
  cosim::WriteFileAtomically(path, id.dump(2) + "\n");
}

std::optional<SweepIdentity> ReadSweepIdentity(const std::string& path) {
  const auto text = cosim::ReadWholeFile(path);
  if (!text) return std::nullopt;
  const auto id = nlohmann::json::parse(*text, nullptr, /*allow_exceptions=*/false);
  if (!id.is_object() || !id.contains("fingerprint") || !id["fingerprint"].is_string() ||
      !id.contains("inputs") || !id["inputs"].is_object()) {
    return std::nullopt;
  }
  SweepIdentity out;
  out.fingerprint = id["fingerprint"].get<std::string>();
  for (const auto& [file, digest] : id["inputs"].items()) {
    if (!digest.is_string()) return std::nullopt;
    out.inputs[file] = digest.get<std::string>();
  }
  return out;
}

std::vector<std::string> ChangedInputs(const std::map<std::string, std::string>& inputs) {
  std::vector<std::string> changed;
  for (const auto& [file, digest] : inputs) {
    const std::string now = config::InputDigestNow(file);
    if (now != digest) {
      changed.push_back(file + (now == config::kUnreadable      ? " (now missing or unreadable)"
                                : digest == config::kUnreadable ? " (unreadable then, present now)"
                                                                : " (its content changed)"));
    }
  }
  return changed;
}

ResultsFile::ResultsFile(std::string path, std::string header, std::FILE* file,
                         std::map<std::int64_t, std::string> rows)
    : path_(std::move(path)), header_(std::move(header)), file_(file), rows_(std::move(rows)) {}

ResultsFile::ResultsFile(ResultsFile&& other) noexcept
    : path_(std::move(other.path_)),
      header_(std::move(other.header_)),
      file_(other.file_),
      rows_(std::move(other.rows_)),
      failed_(other.failed_),
      dropped_(other.dropped_),
      tracking_(other.tracking_),
      identity_path_(std::move(other.identity_path_)),
      identity_spec_(std::move(other.identity_spec_)),
      fingerprint_(std::move(other.fingerprint_)),
      inputs_(std::move(other.inputs_)) {
  other.file_ = nullptr;
}

ResultsFile::~ResultsFile() {
  if (file_) std::fclose(file_);
}

ResultsFile ResultsFile::Create(const std::string& path, const SweepSpec& spec) {
  ResultsFile f(path, JoinCsvLine(ResultsHeader(spec)), nullptr, {});
  f.Rewrite();
  return f;
}

ResultsFile ResultsFile::Resume(const std::string& path, const SweepSpec& spec) {
  const std::string header = JoinCsvLine(ResultsHeader(spec));
  // Read only a regular file of bounded size: a link to a device (/dev/zero)
  // would be read for ever. 1 GiB holds ten million rows of 100 bytes, the
  // most runs a sweep may plan.
  constexpr std::uintmax_t kMaxResultsBytes = std::uintmax_t{1} << 30;
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw std::runtime_error(path +
                             " is not a regular file (a device or a folder?): it cannot "
                             "be this sweep's results; choose another --out");
  }
  if (const auto size = std::filesystem::file_size(path, ec); !ec && size > kMaxResultsBytes) {
    throw std::runtime_error(path + " is " + std::to_string(size) +
                             " bytes, more than the 1 GiB a sweep's results can be: it is not "
                             "this sweep's; choose another --out");
  }
  const std::string text = ReadWhole(path);
  if (text.compare(0, header.size(), header) != 0) {
    throw std::runtime_error(path + " has other columns than this sweep writes (expected " +
                             header.substr(0, header.size() - 1) +
                             "): it is not this sweep's; choose another --out");
  }
  const std::size_t columns = ResultsHeader(spec).size();
  const std::int64_t count = RunCount(spec);
  std::map<std::int64_t, std::string> rows;
  std::int64_t failed = 0, dropped = 0;
  std::size_t start = header.size();
  while (start < text.size()) {
    const std::size_t end = text.find('\n', start);
    // A line without its newline was cut off while being written.
    if (end == std::string::npos) break;
    const std::string line = text.substr(start, end + 1 - start);
    start = end + 1;
    const auto fields = SplitCsvLine(std::string_view(line).substr(0, line.size() - 1));
    if (!fields || fields->size() != columns) continue;
    const auto id = ParseId(fields->front());
    if (!id || *id < 0 || *id >= count) continue;
    if (rows.count(*id) != 0) continue;  // the first of duplicates stands
    const std::vector<std::string> proven_fields(fields->begin(), fields->end() - 2);
    const std::string proven = JoinCsvLine(proven_fields);
    if (RowCheck(std::string_view(proven).substr(0, proven.size() - 1)) != fields->back() ||
        !RowMatchesPlan(spec, PlanRun(spec, *id), *fields)) {
      ++dropped;
      continue;
    }
    rows.emplace(*id, line);
    if ((*fields)[StatusColumn(spec.parameters.size(), spec.metrics.size())] != "ok") ++failed;
  }
  ResultsFile f(path, header, nullptr, std::move(rows));
  f.failed_ = failed;
  f.dropped_ = dropped;
  f.Rewrite();
  return f;
}

void ResultsFile::Rewrite() {
  if (file_) {
    std::fclose(file_);
    file_ = nullptr;
  }
  std::string text = header_;
  for (const auto& [id, line] : rows_) text += line;
  cosim::WriteFileAtomically(path_, text);
  file_ = OpenOrThrow(path_, "ab");
}

void ResultsFile::TrackInputs(std::string identity_path, const SweepSpec& spec,
                              std::string fingerprint, std::map<std::string, std::string> inputs) {
  tracking_ = true;
  identity_path_ = std::move(identity_path);
  identity_spec_ = spec;
  fingerprint_ = std::move(fingerprint);
  inputs_ = std::move(inputs);
}

void ResultsFile::Append(std::int64_t id, const std::string& line, bool ok,
                         const std::map<std::string, std::string>& inputs) {
  if (tracking_) {
    // The row stands for the files its run read: each must be what every
    // other row's run read (a file edited during the sweep would mix two
    // models in one table), and sweep.json must name it before the row is
    // written, so that --resume checks it.
    bool added = false;
    for (const auto& [file, digest] : inputs) {
      const auto [it, fresh] = inputs_.emplace(file, digest);
      added = added || fresh;
      if (!fresh && it->second != digest) {
        throw std::runtime_error(
            file + " changed during the sweep: run " + std::to_string(id) +
            " read other bytes than the runs before it (SHA-256 " + digest.substr(0, 12) +
            " against " + it->second.substr(0, 12) +
            "); its row is not written. Rows of two versions of a file would mix two models: "
            "--force starts the sweep afresh");
      }
    }
    if (added) WriteSweepIdentity(identity_path_, identity_spec_, fingerprint_, inputs_);
  }
  // One write and a flush per row: a kill loses at most the line being
  // written, which a resumed sweep drops and runs again.
  if (std::fputs(line.c_str(), file_) < 0 || std::fflush(file_) != 0) {
    throw std::runtime_error("cannot write " + path_ + ": " + std::strerror(errno));
  }
  if (rows_.emplace(id, line).second && !ok) ++failed_;
}

void ResultsFile::SortByRunId() { Rewrite(); }

SweepTable ResultsFile::Table(const SweepSpec& spec) const {
  SweepTable t;
  t.name = spec.name;
  t.grid = spec.combination == Combination::kGrid;
  for (const auto& p : spec.parameters) {
    t.parameters.push_back(p.path);
    t.levels.push_back(p.kind == ParameterKind::kRandom ? std::vector<std::string>{} : p.values);
  }
  t.metrics = spec.metrics;
  t.metrics.push_back("wall_s");
  t.reference = spec.reference;
  const std::size_t np = spec.parameters.size();
  const std::size_t nm = spec.metrics.size();
  for (const auto& [id, line] : rows_) {
    const auto fields = SplitCsvLine(std::string_view(line).substr(0, line.size() - 1));
    if (!fields) continue;
    const auto& f = *fields;
    SweepTable::Row row;
    row.id = id;
    row.values.assign(f.begin() + 1, f.begin() + 1 + static_cast<std::ptrdiff_t>(np));
    row.seed = std::strtoull(f[1 + np].c_str(), nullptr, 10);
    for (std::size_t m = 0; m < nm; ++m) row.metrics.push_back(ParseNumber(f[2 + np + m]));
    row.ok = f[StatusColumn(np, nm)] == "ok";
    row.error = f[3 + np + nm];
    row.error_unit = f[4 + np + nm];
    if (const auto time = cosim::ParseFiniteValue(f[5 + np + nm])) row.error_time_s = *time;
    row.error_phase = f[6 + np + nm];
    row.error_variable = f[7 + np + nm];
    row.error_cause = f[8 + np + nm];
    row.metrics.push_back(ParseNumber(f[WallColumn(np, nm)]));
    t.rows.push_back(std::move(row));
  }
  return t;
}

}  // namespace linesim::sweep
