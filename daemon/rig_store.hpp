#pragma once
// The daemon's side of the rig model (pipelines/rig/rig_model.hpp): rig.json in
// the state directory, written atomically through StateFile (the previous good
// version kept as rig.json.bak), with one PLY file per projector for a
// non-planar surface. A calibration merges into the file; nothing else writes it.
#include <map>
#include <string>

#include "core/error.hpp"
#include "rig/rig_model.hpp"
#include "state_file.hpp"

namespace procam::daemon {

inline constexpr const char* kRigFileName = "rig.json";

StateFile rigStateFile(const std::string& state_dir);

struct LoadedRig {
  rig::RigModel rig;    // empty when the state directory has no rig.json
  std::string path;     // of rig.json
  std::string warning;  // set when the backup was used
};

// kParse when rig.json and its backup are both unusable; no file is an empty rig.
Result<LoadedRig> loadRig(const std::string& state_dir);

// The file name of `projector`'s surface mesh beside rig.json.
std::string meshFileName(const std::string& projector);

// Writes `meshes` (file name -> PLY text), then the rig read again from the state
// directory merged with `update`; returns the merged model. On an error rig.json
// is unchanged.
Result<rig::RigModel> mergeIntoRig(const std::string& state_dir, const rig::RigModel& update,
                                   const std::map<std::string, std::string>& meshes);

// procamd --rig FILE: FILE checked as a rig model and installed as the state
// directory's rig.json (replacing what was there, which stays as the backup). The mesh
// files it names (surface meshes, the object's model) that lie beside FILE are copied
// into the state directory with it; one that does not is looked for there.
Result<rig::RigModel> importRig(const std::string& state_dir, const std::string& file);

// Now as ISO 8601 UTC, for provenance records.
std::string utcNow();

}  // namespace procam::daemon
