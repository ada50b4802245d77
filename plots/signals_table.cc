#include "plots/signals_table.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "cosim/closest_names.h"
#include "cosim/variable_table.h"

namespace linesim::plots::table {

namespace fs = std::filesystem;

void SplitCsv(std::string_view line, std::vector<std::string_view>& fields,
              std::size_t max_fields) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  fields.clear();
  std::size_t begin = 0;
  while (max_fields == 0 || fields.size() < max_fields) {
    const std::size_t comma = line.find(',', begin);
    fields.push_back(line.substr(begin, comma - begin));
    if (comma == std::string_view::npos) break;
    begin = comma + 1;
  }
}

std::optional<double> Column(const std::vector<std::string_view>& fields, int col) {
  if (col < 1 || static_cast<std::size_t>(col) > fields.size()) return std::nullopt;
  return cosim::ParseFiniteValue(fields[static_cast<std::size_t>(col - 1)]);
}

Signals OpenSignals(const fs::path& file) {
  Signals s{file, std::ifstream(file, std::ios::binary), {}, {}};
  if (!s.in) {
    throw std::runtime_error("cannot read " + file.string() + ": " + std::strerror(errno));
  }
  std::string line;
  if (!std::getline(s.in, line)) throw std::runtime_error(file.string() + " is empty");
  std::vector<std::string_view> fields;
  SplitCsv(line, fields);
  s.header.assign(fields.begin(), fields.end());
  return s;
}

void ReadRow(Signals& signals, std::size_t row, std::string& line,
             std::vector<std::string_view>& fields) {
  signals.in.clear();
  signals.in.seekg(signals.row_starts[row]);
  if (!std::getline(signals.in, line)) {
    throw std::runtime_error("cannot read " + signals.file.string() + " again at row " +
                             std::to_string(row + 1));
  }
  SplitCsv(line, fields);
}

std::size_t RowAt(Signals& signals, double t) {
  std::string line;
  std::vector<std::string_view> fields;
  std::size_t lo = 0, hi = signals.row_starts.size() - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    ReadRow(signals, mid, line, fields);
    const auto tm = Column(fields, 1);
    if (tm && *tm < t) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

int ColumnFinder::operator()(const std::string& name, const char* role) {
  if (name.empty()) return 0;
  const auto it = std::find(header_.begin(), header_.end(), name);
  if (it != header_.end()) return static_cast<int>(it - header_.begin()) + 1;
  unknown_.push_back("no column '" + name + "' (" + role + ")" + cosim::ClosestHint(name, header_));
  return 0;
}

void ColumnFinder::ThrowIfUnknown() const {
  if (unknown_.empty()) return;
  std::string text = file_.string() + ": ";
  for (std::size_t i = 0; i < unknown_.size(); ++i) text += (i ? "; " : "") + unknown_[i];
  throw std::runtime_error(text);
}

void DataColumns::Use(int csv) { UseScaled(csv, 1.0); }

void DataColumns::UseScaled(int csv, double factor) {
  if (csv <= 0 || Has(csv)) return;
  if (static_cast<std::size_t>(csv) >= block_of_.size()) block_of_.resize(csv + 1, 0);
  csv_.push_back(csv);
  scale_.push_back(factor);
  block_of_[static_cast<std::size_t>(csv)] = static_cast<int>(csv_.size());
}

int DataColumns::operator[](int csv) const {
  if (!Has(csv)) {
    throw std::logic_error("robot plots: column " + std::to_string(csv) + " not in $signals");
  }
  return block_of_[static_cast<std::size_t>(csv)];
}

void DataColumns::AppendRow(const std::vector<std::string_view>& fields, std::string& block) const {
  for (std::size_t k = 0; k < csv_.size(); ++k) {
    if (k) block += ',';
    const auto i = static_cast<std::size_t>(csv_[k] - 1);
    if (i >= fields.size()) continue;
    if (scale_[k] == 1.0) {
      block += fields[i];
    } else if (const auto v = cosim::ParseFiniteValue(fields[i])) {
      block += cosim::FormatValue(*v * scale_[k]);
    }
  }
  block += '\n';
}

bool DataColumns::Has(int csv) const {
  return csv > 0 && static_cast<std::size_t>(csv) < block_of_.size() &&
         block_of_[static_cast<std::size_t>(csv)] > 0;
}

}  // namespace linesim::plots::table
