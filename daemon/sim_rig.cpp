#include "sim_rig.hpp"

#ifdef PROCAM_HAVE_SIM
#include "sim/scene_library.hpp"
#endif

namespace procam::daemon {

Result<std::vector<plugins::DeviceDescription>> simDevices(const std::string& scene_name) {
#ifdef PROCAM_HAVE_SIM
  auto scene = sim::resolveScene(scene_name);
  if (!scene) return tl::unexpected(scene.error());
  std::vector<plugins::DeviceDescription> out;
  auto add = [&](procam_family family, const std::string& name) {
    plugins::DeviceDescription d;
    d.family = family;
    d.subsystem = "sim";
    d.name = name;
    d.properties = {{"PROCAM_ROLE", plugins::familyName(family)},
                    {"SIM_SCENE", scene_name},
                    {"SIM_DEVICE", name}};
    out.push_back(std::move(d));
  };
  for (const auto& p : scene->projectors()) add(PROCAM_FAMILY_OUTPUT, p.name);
  for (const auto& c : scene->cameras()) add(PROCAM_FAMILY_CAMERA, c.name);
  for (const auto& t : scene->tiltSensors()) add(PROCAM_FAMILY_TILT, t.name);
  for (const auto& t : scene->trackers()) add(PROCAM_FAMILY_TRACKER, t.name);
  return out;
#else
  return fail(ErrorCode::kIo, "this procamd was built without the virtual rig; cannot run scene '" +
                                  scene_name + "'");
#endif
}

}  // namespace procam::daemon
