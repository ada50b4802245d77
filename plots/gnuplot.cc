#include "plots/gnuplot.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

extern char** environ;

namespace linesim::plots {

namespace fs = std::filesystem;

std::string GnuplotQuote(const std::string& text) {
  std::string out = "'";
  for (char c : text) {
    if (c == '\'') {
      out += "''";
    } else if (c == '\n' || c == '\r') {
      out += ' ';
    } else {
      out += c;
    }
  }
  return out + "'";
}

std::string GnuplotPngTerminal(int width_px, int height_px) {
  const std::string size = std::to_string(width_px) + "," + std::to_string(height_px);
  return "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
         "  set terminal pngcairo size " +
         size +
         " noenhanced font ',10'\n"
         "} else {\n"
         "  set terminal png size " +
         size +
         " noenhanced\n"
         "}\n";
}

std::string_view PlotExtension(PlotFormat format) {
  switch (format) {
    case PlotFormat::kSvg:
      return "svg";
    case PlotFormat::kPdf:
      return "pdf";
    case PlotFormat::kPng:
      break;
  }
  return "png";
}

std::optional<PlotFormat> ParsePlotFormat(std::string_view text) {
  for (PlotFormat f : {PlotFormat::kPng, PlotFormat::kSvg, PlotFormat::kPdf}) {
    if (text == PlotExtension(f)) return f;
  }
  return std::nullopt;
}

std::string PlotFile(const std::string& name, PlotFormat format) {
  return name + "." + std::string(PlotExtension(format));
}

std::string GnuplotTerminal(PlotFormat format, int width_px, int height_px) {
  switch (format) {
    case PlotFormat::kSvg:
      return "set terminal svg size " + std::to_string(width_px) + "," + std::to_string(height_px) +
             " noenhanced font ',13.33' background rgb 'white'\n";
    case PlotFormat::kPdf: {
      // pdfcairo takes inches: 100 pixels to the inch keeps the PNG's layout.
      const auto inches = [](int px) {
        return std::to_string(px / 100) + "." + std::to_string((px % 100) / 10) +
               std::to_string(px % 10);
      };
      return "set terminal pdfcairo size " + inches(width_px) + "in," + inches(height_px) +
             "in noenhanced font ',10'\n";
    }
    case PlotFormat::kPng:
      break;
  }
  return GnuplotPngTerminal(width_px, height_px);
}

GnuplotResult RunGnuplot(const std::string& dir, const std::string& script_name) {
  int err_pipe[2];
  if (pipe(err_pipe) != 0) {
    throw std::runtime_error(std::string("cannot create a pipe for gnuplot: ") +
                             std::strerror(errno));
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_adddup2(&actions, err_pipe[1], 2);
  posix_spawn_file_actions_addclose(&actions, err_pipe[0]);
  posix_spawn_file_actions_addclose(&actions, err_pipe[1]);
  posix_spawn_file_actions_addchdir_np(&actions, dir.c_str());
  std::string arg0 = "gnuplot", arg1 = script_name;
  char* argv[] = {arg0.data(), arg1.data(), nullptr};
  pid_t pid = 0;
  const int spawn_error = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  close(err_pipe[1]);
  if (spawn_error != 0) {
    close(err_pipe[0]);
    throw std::runtime_error("cannot run gnuplot (is it installed and on PATH?): " +
                             std::string(std::strerror(spawn_error)));
  }
  GnuplotResult result;
  char buf[4096];
  while (true) {
    const ssize_t n = read(err_pipe[0], buf, sizeof buf);
    if (n > 0) {
      result.errors.append(buf, static_cast<std::size_t>(n));
    } else if (n == 0 || errno != EINTR) {
      break;
    }
  }
  close(err_pipe[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) throw std::runtime_error("waiting for gnuplot failed");
  }
  result.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return result;
}

std::vector<std::string> DrawWithGnuplot(const std::string& dir, const std::string& script_name,
                                         const std::string& script,
                                         const std::vector<std::string>& outputs) {
  const fs::path folder(dir);
  const fs::path script_path = folder / script_name;
  {
    std::ofstream out(script_path, std::ios::binary | std::ios::trunc);
    out << script;
    if (!out.flush()) throw std::runtime_error("cannot write " + script_path.string());
  }
  // Stale plots from an earlier run must not pass for new ones.
  for (const auto& name : outputs) fs::remove(folder / name);
  const GnuplotResult run = RunGnuplot(dir, script_name);
  std::vector<std::string> written;
  for (const auto& name : outputs) {
    const fs::path file = folder / name;
    if (run.exit_status == 0 && !fs::exists(file)) {
      throw std::runtime_error("gnuplot did not write " + file.string() + ": " + run.errors);
    }
    written.push_back(file.string());
  }
  if (run.exit_status != 0) {
    throw std::runtime_error("gnuplot failed on " + script_path.string() + " (exit status " +
                             std::to_string(run.exit_status) + "): " + run.errors);
  }
  return written;
}

}  // namespace linesim::plots
