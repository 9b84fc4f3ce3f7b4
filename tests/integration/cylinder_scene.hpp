#pragma once
// cylinder3's scene text, and the same rig with lenses on its projectors: barrel and
// pincushion of 1.6-3.4 px at the frame's corners (0.2-0.5 % of its half diagonal, as
// projection lenses have), which a pinhole leaves out and the post-rendering warp puts
// back ([Raskar02] §4.1.3).
#include <gtest/gtest.h>

#include <string>

#include "sim/embedded_scenes.hpp"

namespace procam::itest {

inline std::string cylinder3Text() {
  for (std::size_t i = 0; i < sim::detail::kEmbeddedSceneCount; ++i) {
    if (sim::detail::kEmbeddedScenes[i].name == "cylinder3")
      return std::string(sim::detail::kEmbeddedScenes[i].text);
  }
  ADD_FAILURE() << "no built-in cylinder3";
  return "";
}

inline std::string withProjectorLenses(std::string text) {
  const char* lenses[] = {"{ k1 = -0.012, k2 = 0.004 }", "{ k1 = 0.008 }",
                          "{ k1 = -0.015, p1 = 0.0004 }"};
  std::size_t at = 0;
  for (const char* lens : lenses) {
    at = text.find("intrinsics = { hfov_deg = 50.0 }\n", at);
    if (at == std::string::npos) {
      ADD_FAILURE() << "cylinder3 has fewer than three projectors";
      return text;
    }
    at = text.find('\n', at) + 1;
    text.insert(at, "distortion = " + std::string(lens) + "\n");
  }
  return text;
}

}  // namespace procam::itest
