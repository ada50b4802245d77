#pragma once

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

/// Reading signals.csv for the robot figures (plots/ only): row by row,
/// never held whole, columns found by name with every unknown one named.
namespace linesim::plots::table {

/// Views of the first `max_fields` fields of a CSV line (all when 0), into
/// a vector reused from row to row: no allocation per field.
void SplitCsv(std::string_view line, std::vector<std::string_view>& fields,
              std::size_t max_fields = 0);

/// 1-based column `col` of a split row as a finite number; nothing when
/// missing, empty or not finite (left out of the plots).
std::optional<double> Column(const std::vector<std::string_view>& fields, int col);

/// signals.csv, open after its header.
struct Signals {
  std::filesystem::path file;
  std::ifstream in;
  std::vector<std::string> header;
  /// Where each data row starts (filled by the pass that reads them all).
  std::vector<std::streamoff> row_starts;
};

/// Opens `file` and reads its header; throws std::runtime_error naming
/// the file when it cannot be read or is empty.
Signals OpenSignals(const std::filesystem::path& file);

/// Data row `row` of `signals` again, split into `fields`.
void ReadRow(Signals& signals, std::size_t row, std::string& line,
             std::vector<std::string_view>& fields);

/// The first data row whose time (column 1) is at least `t` (rows are in
/// time order); the last row when none is.
std::size_t RowAt(Signals& signals, double t);

/// 1-based column numbers (as gnuplot's `using` counts) by name; every
/// unknown name is collected so that one error lists them all.
class ColumnFinder {
 public:
  ColumnFinder(const std::vector<std::string>& header, std::filesystem::path file)
      : header_(header), file_(std::move(file)) {}

  /// The column of `name` (0 when `name` is empty: not asked for);
  /// `role` says what it is for in the error.
  int operator()(const std::string& name, const char* role);
  /// Throws std::runtime_error listing every unknown column with the
  /// closest known names.
  void ThrowIfUnknown() const;

 private:
  const std::vector<std::string>& header_;
  std::filesystem::path file_;
  std::vector<std::string> unknown_;
};

/// The columns of signals.csv the time plots draw, copied as text into the
/// script's $signals block in the pass that reads the file anyway: gnuplot
/// reads them there instead of parsing every row of signals.csv once per
/// curve (in a fleet some 60 columns per robot). Block columns in order of
/// first use; time is always the first.
class DataColumns {
 public:
  DataColumns() { Use(1); }
  /// Adds CSV column `csv` (1-based; 0: none, ignored).
  void Use(int csv);
  /// Adds CSV column `csv` as its values times `factor` (a deviation in m
  /// as mm: gnuplot then reads the column instead of evaluating a product
  /// per row).
  void UseScaled(int csv, double factor);
  /// The block column (1-based, as gnuplot counts) of CSV column `csv`.
  int operator[](int csv) const;
  /// "column(N)" of CSV column `csv` in the block, for expressions.
  std::string Expr(int csv) const { return "column(" + std::to_string((*this)[csv]) + ")"; }
  std::size_t last_csv() const { return block_of_.size() - 1; }
  /// One row of the block from the fields of a row of signals.csv (as
  /// text: gnuplot reads the same characters it would have read there).
  void AppendRow(const std::vector<std::string_view>& fields, std::string& block) const;

 private:
  bool Has(int csv) const;
  std::vector<int> csv_;       // block column k + 1 holds CSV column csv_[k]
  std::vector<double> scale_;  // ... times scale_[k] (1: copied as text)
  std::vector<int> block_of_;  // CSV column -> block column (0: not in it)
};

}  // namespace linesim::plots::table
