#pragma once
// Human-readable renderings of procamd's replies and events.
#include <nlohmann/json.hpp>
#include <string>

namespace procam::ctl {

// "[##########··········]  50%  stage" — `width` cells; fraction clamped to [0, 1].
std::string progressBar(double fraction, int width, const std::string& stage);

// Multi-line text for a reply (ends with a newline). A key the reply lacks, or holding
// another type than expected (a procamd of another version), reads as absent ("-" or the
// line left out); never throws.
std::string formatReply(const nlohmann::json& reply);

// One line for an event (ends with a newline).
std::string formatEvent(const nlohmann::json& event);

}  // namespace procam::ctl
