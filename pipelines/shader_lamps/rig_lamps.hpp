#pragma once
// A rig's projectors as shader lamps on one object ([Raskar02] §5.2): what depends only
// on the rig model and the object — each posed projector's view of the object, the
// feathering weights over all of them (§5.2.5), the coverage, each projector's response
// and k·B from its measured brightness, the brightest white all can give — prepared once;
// then any look (texture, material, eye) is drawn per projector by lampFrame (eq. 5.4).
// procam-render --object and procamd's object surface share it.
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "rig/rig_model.hpp"
#include "shader_lamps/appearance.hpp"
#include "shader_lamps/lamp_frame.hpp"
#include "shader_lamps/lamp_view.hpp"
#include "shader_lamps/lamp_weights.hpp"
#include "shader_lamps/object_model.hpp"

namespace procam::lamps {

struct RigLampOptions {
  std::vector<std::string> projectors;  // only these (empty: every posed one)
  std::vector<std::string> off;         // switched off: dark, the part only they reach unlit
  double max_incidence_deg = 60;        // the grazing cut-off (§5.2.5)
};

struct RigLamp {
  std::string name, output;
  geom::CameraModel model;
  LampView view;
  bool on = true;
  LampPhotometry photometry;
  bool response_measured = false;  // else gamma 2.2 assumed
  bool gain_measured = false;      // from the brightness map; else equal for all
  double gain_spread = -1;         // of the brightness over the lit pixels, when measured
};

struct RigLamps {
  std::vector<RigLamp> lamps;  // rig order
  LampWeights weights;
  Coverage coverage;
  double white = 0;   // the brightest white level every projector that is on gives
  std::string units;  // of white and the gains: "camera 'NAME' units" or relative
  double max_incidence_deg = 60;
};

// kNotFound when no projector has a pose (or one asked for has none, or `off` names
// one that is not there); kInvalidInput when some projectors that are on have a measured
// brightness and others not, or two cameras measured them (their gains do not compare),
// or every projector is off; errors of casting the views and of the weights.
Result<RigLamps> prepareRigLamps(const rig::RigModel& rig, const ObjectModel& object,
                                 const RigLampOptions& options = {});

// Lamp i's frame for the look (lampFrame's form; black when it is off). `white` <= 0
// takes the prepared one.
Result<cv::Mat> rigLampFrame(const RigLamps& lamps, std::size_t i, const Material& material,
                             double white, const std::optional<Vec3>& eye,
                             LampFrameStats* stats = nullptr, int bit_depth = 8);

// {white, units, max_incidence_deg, coverage: {lit_m2, unlit_m2, unlit_faces,
// never_lit_m2}} and per projector {name, output, on, response_gamma, response, gain,
// gain_source, gain_spread}.
nlohmann::json describeDisplay(const RigLamps& lamps, double white);
nlohmann::json describeLamp(const RigLamp& lamp);

// sRGB codes (8 or 16 bit, grey, BGR or BGRA as OpenCV decodes them) as linear RGB floats.
cv::Mat linearTexture(const cv::Mat& image);

}  // namespace procam::lamps
