#pragma once

// A RunError as JSON, the same object in `linesim run`'s and a sweep's
// summary.json: {"unit", "time_s", "phase", "variable", "cause", "message"},
// null for a field that does not apply. Header-only: cosim itself does not
// depend on a JSON library.

#include <nlohmann/json.hpp>

#include "cosim/run_error.h"

namespace linesim::cosim {

inline nlohmann::ordered_json RunErrorJson(const RunError& e) {
  using Json = nlohmann::ordered_json;
  const auto text_or_null = [](const std::string& s) { return s.empty() ? Json(nullptr) : Json(s); };
  Json j;
  j["unit"] = text_or_null(e.unit);
  j["time_s"] = e.time ? Json(NsToSeconds(*e.time)) : Json(nullptr);
  j["phase"] = std::string(ToString(e.phase));
  j["variable"] = text_or_null(e.variable);
  j["cause"] = e.cause;
  j["message"] = e.message;
  return j;
}

}  // namespace linesim::cosim
