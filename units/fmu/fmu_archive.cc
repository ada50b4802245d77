#include "units/fmu/fmu_archive.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>
#include <zip.h>

#include <array>
#include <atomic>
#include <cerrno>
#include <charconv>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <filesystem>
#include <memory>
#include <string_view>
#include <system_error>
#include <vector>

#include "units/fmu/model_description.h"

namespace linesim::fmu {

namespace fs = std::filesystem;

namespace {

// The live folders, for removal at exit and from signal handlers: fixed
// slots of heap copies (a handler only reads them), claimed and released
// with atomic exchanges.
constexpr std::size_t kMaxLiveFolders = 256;
std::array<std::atomic<char*>, kMaxLiveFolders> g_live{};

// Removes the tree at `dir` (relative to `parent`) with system calls only:
// openat, getdents64, unlinkat (async-signal-safe; no readdir, which may
// allocate). Does not follow links. `depth` bounds the recursion.
void RemoveTreeAt(int parent, const char* name, int depth) noexcept {
  if (depth > 64) return;
  const int fd = openat(parent, name, O_RDONLY | O_DIRECTORY | O_NOFOLLOW | O_CLOEXEC);
  if (fd >= 0) {
    alignas(8) char buffer[4096];
    for (;;) {
      const long n = syscall(SYS_getdents64, fd, buffer, sizeof buffer);
      if (n <= 0) break;
      for (long at = 0; at < n;) {
        // struct linux_dirent64: ino (8), off (8), reclen (2), type (1), name.
        unsigned short reclen = 0;
        std::memcpy(&reclen, buffer + at + 16, sizeof reclen);
        const unsigned char type = static_cast<unsigned char>(buffer[at + 18]);
        const char* entry = buffer + at + 19;
        at += reclen;
        if (std::strcmp(entry, ".") == 0 || std::strcmp(entry, "..") == 0) continue;
        if (type == DT_DIR) {
          RemoveTreeAt(fd, entry, depth + 1);
        } else if (unlinkat(fd, entry, 0) != 0 && errno == EISDIR) {
          RemoveTreeAt(fd, entry, depth + 1);
        }
      }
    }
    close(fd);
  }
  unlinkat(parent, name, AT_REMOVEDIR);
}

extern "C" void RemoveAtExit() { RemoveLiveTempFolders(); }

// Crash signals, SIGTERM and SIGINT, while nobody else handles them:
// remove the folders, then die of the signal as before (the handler is
// reset to the default by SA_RESETHAND).
extern "C" void RemoveOnSignal(int sig) {
  RemoveLiveTempFolders();
  raise(sig);
}

void InstallCleanupOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    std::atexit(RemoveAtExit);
    struct sigaction action {};
    action.sa_handler = RemoveOnSignal;
    action.sa_flags = SA_RESETHAND | SA_NODEFER;
    sigemptyset(&action.sa_mask);
    // Only where nobody else handles the signal: a sanitizer's or a
    // debugger's handler (and its report) stays.
    for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT, SIGTERM, SIGINT}) {
      struct sigaction old {};
      if (sigaction(sig, nullptr, &old) == 0 && old.sa_handler == SIG_DFL &&
          !(old.sa_flags & SA_SIGINFO)) {
        sigaction(sig, &action, nullptr);
      }
    }
    SweepStaleTempFolders();
  });
}

constexpr std::string_view kPrefix = "linesim-fmu-";

}  // namespace

void RemoveLiveTempFolders() noexcept {
  for (auto& slot : g_live) {
    char* path = slot.exchange(nullptr);
    if (path) RemoveTreeAt(AT_FDCWD, path, 0);
    // Not freed: a handler must not call free, and the process is ending.
  }
}

std::size_t SweepStaleTempFolders() {
  std::error_code ec;
  fs::path base = fs::temp_directory_path(ec);
  if (ec) base = "/tmp";
  std::size_t removed = 0;
  const pid_t self = getpid();
  for (const auto& entry : fs::directory_iterator(base, ec)) {
    const std::string name = entry.path().filename().string();
    // linesim-fmu-<pid>-XXXXXX: the pid in decimal, then mkdtemp's six.
    if (name.compare(0, kPrefix.size(), kPrefix) != 0) continue;
    const std::size_t dash = name.find('-', kPrefix.size());
    if (dash == std::string::npos || dash == kPrefix.size() || name.size() != dash + 7) continue;
    long pid = 0;
    const auto [end, err] = std::from_chars(name.data() + kPrefix.size(), name.data() + dash, pid);
    if (err != std::errc() || end != name.data() + dash || pid <= 0 || pid == self) continue;
    struct stat st {};
    if (lstat(entry.path().c_str(), &st) != 0 || !S_ISDIR(st.st_mode) || st.st_uid != geteuid()) {
      continue;
    }
    if (kill(static_cast<pid_t>(pid), 0) == 0 || errno != ESRCH) continue;  // alive (or not ours to judge)
    std::error_code remove_ec;
    fs::remove_all(entry.path(), remove_ec);
    if (!remove_ec) ++removed;
  }
  return removed;
}

TempFolder::TempFolder() {
  InstallCleanupOnce();
  std::error_code ec;
  fs::path base = fs::temp_directory_path(ec);
  if (ec) base = "/tmp";
  std::string pattern =
      (base / (std::string(kPrefix) + std::to_string(getpid()) + "-XXXXXX")).string();
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (!mkdtemp(buffer.data())) {
    throw FmuError("cannot create a temporary folder in " + base.string() + ": " +
                   std::strerror(errno));
  }
  path_ = buffer.data();
  char* copy = strdup(path_.c_str());
  for (auto& slot : g_live) {
    char* expected = nullptr;
    if (copy && slot.compare_exchange_strong(expected, copy)) {
      copy = nullptr;
      break;
    }
  }
  std::free(copy);  // more than kMaxLiveFolders at once: removed by the destructor only
}

TempFolder::~TempFolder() {
  for (auto& slot : g_live) {
    char* p = slot.load();
    if (p && path_ == p && slot.compare_exchange_strong(p, nullptr)) {
      std::free(p);
      break;
    }
  }
  std::error_code ec;
  fs::remove_all(path_, ec);
}

namespace {

// Why `name` (an entry of the archive) could land outside the folder, or
// nothing.
std::string UnsafeName(std::string_view name) {
  if (name.empty()) return "an empty name";
  if (name.front() == '/') return "an absolute path";
  if (name.find('\\') != std::string_view::npos) return "a backslash";
  if (name.size() >= 2 && name[1] == ':') return "a drive letter (an absolute path)";
  if (name.find('\0') != std::string_view::npos) return "a NUL character";
  std::size_t pos = 0;
  while (pos <= name.size()) {
    const std::size_t slash = std::min(name.find('/', pos), name.size());
    if (name.substr(pos, slash - pos) == "..") return "a '..' component";
    pos = slash + 1;
  }
  return "";
}

struct ZipCloser {
  void operator()(zip_t* z) const { zip_discard(z); }
};
struct ZipFileCloser {
  void operator()(zip_file_t* f) const { zip_fclose(f); }
};

}  // namespace

void Unpack(const std::string& fmu, const std::string& folder) {
  int error = 0;
  std::unique_ptr<zip_t, ZipCloser> archive(zip_open(fmu.c_str(), ZIP_RDONLY, &error));
  if (!archive) {
    zip_error_t ze;
    zip_error_init_with_code(&ze, error);
    const std::string why = zip_error_strerror(&ze);
    zip_error_fini(&ze);
    throw FmuError(fmu + ": not a readable FMU (zip archive): " + why);
  }
  const zip_int64_t count = zip_get_num_entries(archive.get(), 0);
  // First every name and kind, so that a bad entry refuses the FMU before
  // anything is written.
  std::uint64_t total = 0;
  for (zip_int64_t i = 0; i < count; ++i) {
    const auto index = static_cast<zip_uint64_t>(i);
    const char* raw = zip_get_name(archive.get(), index, ZIP_FL_ENC_RAW);
    if (!raw) throw FmuError(fmu + ": entry " + std::to_string(i) + " has no readable name");
    const std::string name = raw;
    if (const std::string why = UnsafeName(name); !why.empty()) {
      throw FmuError(fmu + ": refused: entry '" + name + "' has " + why +
                     " (it could be written outside the FMU's folder)");
    }
    zip_uint8_t opsys = 0;
    zip_uint32_t attributes = 0;
    if (zip_file_get_external_attributes(archive.get(), index, 0, &opsys, &attributes) == 0 &&
        opsys == ZIP_OPSYS_UNIX) {
      const mode_t mode = static_cast<mode_t>(attributes >> 16);
      if (S_ISLNK(mode)) {
        throw FmuError(fmu + ": refused: entry '" + name +
                       "' is a symbolic link (it could point outside the FMU's folder)");
      }
      // Permissions without file-type bits (Python's zipfile.writestr
      // writes 0600 << 16) say nothing of the kind: a file, or a folder
      // when the name ends in '/'. Type bits that are neither (a FIFO, a
      // device) are refused.
      if ((mode & S_IFMT) != 0 && !S_ISREG(mode) && !S_ISDIR(mode)) {
        throw FmuError(fmu + ": refused: entry '" + name + "' is not a file or a folder");
      }
    }
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_stat_index(archive.get(), index, 0, &st) == 0 && (st.valid & ZIP_STAT_SIZE)) {
      total += st.size;
      if (total > kMaxUnpackedBytes) {
        throw FmuError(fmu + ": refused: it unpacks to more than " +
                       std::to_string(kMaxUnpackedBytes >> 30) + " GiB");
      }
    }
  }
  const fs::path root(folder);
  std::vector<char> buffer(1 << 16);
  for (zip_int64_t i = 0; i < count; ++i) {
    const auto index = static_cast<zip_uint64_t>(i);
    const std::string name = zip_get_name(archive.get(), index, ZIP_FL_ENC_RAW);
    const fs::path target = root / name;
    std::error_code ec;
    if (name.back() == '/') {
      fs::create_directories(target, ec);
      if (ec) throw FmuError(fmu + ": cannot create folder '" + name + "': " + ec.message());
      continue;
    }
    fs::create_directories(target.parent_path(), ec);
    if (ec) throw FmuError(fmu + ": cannot create the folder of '" + name + "': " + ec.message());
    // No component of the parent may be a link (none is: links were refused
    // and folders are made here), checked once more before writing.
    const fs::path parent = fs::canonical(target.parent_path(), ec);
    const fs::path canonical_root = fs::canonical(root);
    if (ec || parent.string().rfind(canonical_root.string(), 0) != 0) {
      throw FmuError(fmu + ": refused: entry '" + name + "' resolves outside the FMU's folder");
    }
    std::unique_ptr<zip_file_t, ZipFileCloser> in(zip_fopen_index(archive.get(), index, 0));
    if (!in) {
      throw FmuError(fmu + ": cannot read entry '" + name + "': " +
                     zip_strerror(archive.get()));
    }
    const int fd = ::open(target.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC,
                          0700);
    if (fd < 0) {
      throw FmuError(fmu + ": cannot write entry '" + name + "' (twice in the archive?): " +
                     std::strerror(errno));
    }
    std::uint64_t written = 0;
    for (;;) {
      const zip_int64_t n = zip_fread(in.get(), buffer.data(), buffer.size());
      if (n < 0) {
        ::close(fd);
        throw FmuError(fmu + ": entry '" + name + "' is damaged: " + zip_file_strerror(in.get()));
      }
      if (n == 0) break;
      written += static_cast<std::uint64_t>(n);
      if (written > kMaxUnpackedBytes) {
        ::close(fd);
        throw FmuError(fmu + ": refused: entry '" + name + "' unpacks to more than declared");
      }
      const char* p = buffer.data();
      std::size_t left = static_cast<std::size_t>(n);
      while (left > 0) {
        const ssize_t w = ::write(fd, p, left);
        if (w < 0) {
          if (errno == EINTR) continue;
          const std::string why = std::strerror(errno);
          ::close(fd);
          throw FmuError(fmu + ": cannot write entry '" + name + "': " + why);
        }
        p += w;
        left -= static_cast<std::size_t>(w);
      }
    }
    ::close(fd);
  }
}

}  // namespace linesim::fmu
