#include "plots/figure_style.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <iomanip>
#include <locale>
#include <sstream>

namespace linesim::plots::style {

namespace {

// DejaVu Sans Book's advance widths of the printable ASCII characters
// ' ' (32) to '~' (126), in font units of 2048 per em (its hmtx table, read
// with FreeType's FT_LOAD_NO_SCALE from /usr/share/fonts/truetype/dejavu/
// DejaVuSans.ttf, fonts-dejavu-core 2.37).
constexpr std::array<int, 95> kAdvance = {
    651,  821,  942,  1716, 1303, 1946, 1597, 563,  799,  799,  1024, 1716, 651,  739,  651,  690,
    1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 1303, 690,  690,  1716, 1716, 1716, 1087,
    2048, 1401, 1405, 1430, 1577, 1294, 1178, 1587, 1540, 604,  604,  1343, 1141, 1767, 1532, 1612,
    1235, 1612, 1423, 1300, 1251, 1499, 1401, 2025, 1403, 1251, 1403, 799,  690,  799,  1716, 1024,
    1024, 1255, 1300, 1126, 1300, 1260, 721,  1300, 1298, 569,  569,  1186, 569,  1995, 1298, 1253,
    1300, 1300, 842,  1067, 803,  1298, 1212, 1675, 1212, 1212, 1075, 1303, 690,  1303, 1716};
constexpr double kUnitsPerEm = 2048.0;
constexpr int kWideAdvance = 1767;  // 'M'

// gnuplot's estimate of a character's width in the key (its h_char: 0.6 em
// on the SVG terminal; pngcairo measures its font, narrower for DejaVu
// Sans) and of a key row's height (1.5 em on SVG, about 1.2 em on
// pngcairo): the larger, so that the band holds either.
constexpr double kKeyCharEm = 0.6;
constexpr double kKeyRowEm = 1.5;
// Beside each title: the sample (gnuplot's samplen 4 characters) and the
// gaps around it (measured on the SVG terminal: a column is 11.6
// characters wider than its longest title).
constexpr double kKeyColumnExtraChars = 12.0;

}  // namespace

double TextWidthEm(std::string_view text) {
  int units = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c >= 32 && c < 127) {
      units += kAdvance[c - 32];
    } else if (c >= 0xC0 || c < 0x80) {
      units += kWideAdvance;  // the first byte of a UTF-8 character, or a control
    }
  }
  return units / kUnitsPerEm;
}

const char* SeriesColour(std::size_t k) {
  static constexpr std::array<const char*, 7> kSeries = {
      colour::kBlue,   colour::kVermillion, colour::kGreen, colour::kPurple,
      colour::kOrange, colour::kSky,        colour::kGrey};
  return kSeries[k % kSeries.size()];
}

std::string BeginFigure(const std::string& name, PlotFormat format,
                        std::vector<std::string>* outputs) {
  const std::string file = PlotFile(name, format);
  if (outputs != nullptr) outputs->push_back(file);
  return "\n# " + file +
         "\nreset\n"
         "set datafile separator comma\n"
         "set grid lc rgb '#D0D0D0' lw 1 dt 3\n"
         "set style textbox opaque noborder\n"
         "set output " +
         GnuplotQuote(file) + "\n";
}

std::string Caption(const std::string& what, const std::string& run) {
  std::string s = "set title " + GnuplotQuote(what);
  if (!run.empty()) s += " . \"\\n\" . " + GnuplotQuote(run);
  return s + "\n";
}

KeyBand KeyBelow(const std::vector<std::string>& titles, Canvas canvas,
                 const std::string& key_title) {
  KeyBand band;
  if (titles.empty()) {
    band.commands = "unset key\n";
    return band;
  }
  std::size_t longest_chars = 0;
  double longest_em = 0.0;
  for (const auto& t : titles) {
    longest_chars = std::max(longest_chars, t.size());
    longest_em = std::max(longest_em, TextWidthEm(t));
  }
  // gnuplot gives a column its longest title's characters at kKeyCharEm;
  // where the font's real width is more, `width` adds characters.
  const int widen = std::max(
      0, static_cast<int>(std::ceil(longest_em / kKeyCharEm - static_cast<double>(longest_chars))));
  const double column_px = (static_cast<double>(longest_chars + static_cast<std::size_t>(widen)) +
                            kKeyColumnExtraChars) *
                           kKeyCharEm * kFontPx;
  // gnuplot fits the columns into the plot area's width, not the canvas':
  // less the y tic labels and the y label on the left.
  const double usable_px = canvas.width_px - 110.0;
  const int columns =
      std::clamp(static_cast<int>(usable_px / column_px), 1, static_cast<int>(titles.size()));
  band.rows = static_cast<int>((titles.size() + static_cast<std::size_t>(columns) - 1) /
                               static_cast<std::size_t>(columns));
  const double bottom = 0.01;
  const int lines = band.rows + (key_title.empty() ? 0 : 1);
  const double height_px = lines * kKeyRowEm * kFontPx + 0.5 * kFontPx;
  band.top_screen = bottom + height_px / canvas.height_px;
  band.commands = "set key at screen 0.5, " + Short(bottom, 4) +
                  " center bottom horizontal Left reverse noautotitle maxcols " +
                  std::to_string(columns) + " width " + std::to_string(widen) +
                  (key_title.empty() ? "" : " title " + GnuplotQuote(key_title)) + "\n";
  return band;
}

double AxisBottomAbove(double key_top_screen, Canvas canvas) {
  // From the key band up: a gap, the x axis label (one line), the x tic
  // labels (one line) and the tics' own offset.
  const double px = (0.6 + 1.5 + 1.5 + 0.6) * kFontPx;
  return key_top_screen + px / canvas.height_px;
}

std::string PlotCommand(const std::vector<PlotItem>& items,
                        const std::vector<PlotItem>& also_in_key) {
  std::string s = "plot ";
  bool first = true;
  const auto add = [&](const std::string& what, const std::string& title) {
    s += (first ? "" : ", \\\n     ") + what +
         (title.empty() ? " notitle" : " title " + GnuplotQuote(title));
    first = false;
  };
  for (const auto& item : items) add(item.data + " " + item.style, item.title);
  for (const auto& item : also_in_key) {
    if (!item.title.empty()) add("keyentry " + item.style, item.title);
  }
  return s + "\n";
}

std::string Panel::Margins() const {
  return "set lmargin at screen " + Short(left, 4) + "\nset rmargin at screen " + Short(right, 4) +
         "\nset bmargin at screen " + Short(bottom, 4) + "\nset tmargin at screen " +
         Short(top, 4) + "\n";
}

std::vector<std::string> Titles(const std::vector<PlotItem>& items) {
  std::vector<std::string> titles;
  for (const auto& item : items) {
    if (!item.title.empty()) titles.push_back(item.title);
  }
  return titles;
}

std::string Short(double x, int digits) {
  std::ostringstream out;
  out.imbue(std::locale::classic());
  out << std::setprecision(digits) << x;
  return out.str();
}

}  // namespace linesim::plots::style
