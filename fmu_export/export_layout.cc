#include "fmu_export/export_layout.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <type_traits>

namespace linesim::fmu_export {

Layout MakeLayout(const cosim::VariableTable& table) {
  Layout layout;
  layout.first_vr.reserve(table.size());
  for (const auto& info : table.infos()) {
    layout.first_vr.push_back(static_cast<std::uint32_t>(layout.variables.size()));
    if (info.type != cosim::VarType::kRealArray) {
      layout.variables.push_back({info.name, info.ref, 0, false, info.type});
      continue;
    }
    for (std::size_t i = 0; i < info.size; ++i) {
      const std::string name =
          info.size == 1 ? info.name : info.name + "[" + std::to_string(i + 1) + "]";
      layout.variables.push_back({name, info.ref, i, true, cosim::VarType::kReal});
    }
  }
  return layout;
}

namespace {

std::uint64_t Fnv1a(const std::string& text, std::uint64_t basis) {
  std::uint64_t h = basis;
  for (const unsigned char c : text) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

// Bytes of a UnitState: "LSUS1", then each field with its length first.
class Writer {
 public:
  template <typename T>
  void Pod(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const char* p = reinterpret_cast<const char*>(&v);
    out.insert(out.end(), p, p + sizeof(T));
  }
  void Text(const std::string& s) {
    Pod<std::uint64_t>(s.size());
    out.insert(out.end(), s.begin(), s.end());
  }
  std::vector<char> out;
};

class Reader {
 public:
  Reader(const char* data, std::size_t size) : p_(data), end_(data + size) {}
  template <typename T>
  T Pod() {
    Need(sizeof(T));
    T v;
    std::memcpy(&v, p_, sizeof(T));
    p_ += sizeof(T);
    return v;
  }
  std::string Text() {
    const auto n = Pod<std::uint64_t>();
    Need(n);
    std::string s(p_, p_ + n);
    p_ += n;
    return s;
  }
  bool done() const { return p_ == end_; }

 private:
  void Need(std::uint64_t n) const {
    if (n > static_cast<std::uint64_t>(end_ - p_)) {
      throw std::runtime_error("serialized FMU state: truncated bytes");
    }
  }
  const char* p_;
  const char* end_;
};

constexpr char kMagic[] = "LSUS1";

}  // namespace

bool IsInt64In3(const cosim::VariableInfo& info) {
  if (info.type != cosim::VarType::kInteger) return false;
  const auto lo = info.rule.lower(), hi = info.rule.upper();
  return (lo && *lo < static_cast<double>(INT32_MIN)) ||
         (hi && *hi > static_cast<double>(INT32_MAX));
}

std::string GuidOf(const std::string& text) {
  const std::uint64_t a = Fnv1a(text, 0xcbf29ce484222325ULL);
  const std::uint64_t b = Fnv1a(text, 0x84222325cbf29ce4ULL);
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "{%08x-%04x-%04x-%04x-%012llx}",
                static_cast<unsigned>(a >> 32), static_cast<unsigned>((a >> 16) & 0xffff),
                static_cast<unsigned>(a & 0xffff), static_cast<unsigned>(b >> 48),
                static_cast<unsigned long long>(b & 0xffffffffffffULL));
  return buffer;
}

std::string GuidOfResources(const std::string& resource, const std::string& scene) {
  return GuidOf(scene.empty() ? resource : resource + "\n--- scene ---\n" + scene);
}

std::vector<char> SerializeState(const cosim::UnitState& state) {
  Writer w;
  w.out.insert(w.out.end(), kMagic, kMagic + 5);
  w.Text(state.type_name);
  w.Pod<std::uint64_t>(state.variables.size());
  for (const auto& v : state.variables) {
    w.Pod<std::uint8_t>(static_cast<std::uint8_t>(v.index()));
    if (const auto* d = std::get_if<double>(&v)) {
      w.Pod(*d);
    } else if (const auto* i = std::get_if<std::int64_t>(&v)) {
      w.Pod(*i);
    } else if (const auto* b = std::get_if<bool>(&v)) {
      w.Pod<std::uint8_t>(*b ? 1 : 0);
    } else if (const auto* s = std::get_if<std::string>(&v)) {
      w.Text(*s);
    } else {
      const auto& a = std::get<std::vector<double>>(v);
      w.Pod<std::uint64_t>(a.size());
      for (double x : a) w.Pod(x);
    }
  }
  w.Pod<std::uint64_t>(state.reals.size());
  for (double x : state.reals) w.Pod(x);
  w.Pod<std::uint64_t>(state.integers.size());
  for (std::int64_t x : state.integers) w.Pod(x);
  w.Pod<std::uint64_t>(state.strings.size());
  for (const auto& s : state.strings) w.Text(s);
  return std::move(w.out);
}

cosim::UnitState DeserializeState(const char* data, std::size_t size) {
  if (size < 5 || std::memcmp(data, kMagic, 5) != 0) {
    throw std::runtime_error("serialized FMU state: not written by a linesim FMU");
  }
  Reader r(data + 5, size - 5);
  cosim::UnitState state;
  state.type_name = r.Text();
  const auto n = r.Pod<std::uint64_t>();
  for (std::uint64_t k = 0; k < n; ++k) {
    switch (r.Pod<std::uint8_t>()) {
      case 0:
        state.variables.emplace_back(r.Pod<double>());
        break;
      case 1:
        state.variables.emplace_back(r.Pod<std::int64_t>());
        break;
      case 2:
        state.variables.emplace_back(r.Pod<std::uint8_t>() != 0);
        break;
      case 3:
        state.variables.emplace_back(r.Text());
        break;
      case 4: {
        const auto m = r.Pod<std::uint64_t>();
        std::vector<double> a;
        for (std::uint64_t i = 0; i < m; ++i) a.push_back(r.Pod<double>());
        state.variables.emplace_back(std::move(a));
        break;
      }
      default:
        throw std::runtime_error("serialized FMU state: unknown value kind");
    }
  }
  const auto nr = r.Pod<std::uint64_t>();
  for (std::uint64_t k = 0; k < nr; ++k) state.reals.push_back(r.Pod<double>());
  const auto ni = r.Pod<std::uint64_t>();
  for (std::uint64_t k = 0; k < ni; ++k) state.integers.push_back(r.Pod<std::int64_t>());
  const auto ns = r.Pod<std::uint64_t>();
  for (std::uint64_t k = 0; k < ns; ++k) state.strings.push_back(r.Text());
  if (!r.done()) throw std::runtime_error("serialized FMU state: trailing bytes");
  return state;
}

}  // namespace linesim::fmu_export
