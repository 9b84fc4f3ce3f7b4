#pragma once
// File formats of procam-calibrate: pattern PNGs and sequence.json, capture
// directories, the correspondence PFM, cameras.json / rig.json (README.md here).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "calibration/projector_calibration.hpp"
#include "core/error.hpp"
#include "geometry/camera_model.hpp"
#include "rig/rig_json.hpp"
#include "structured_light/decoder.hpp"
#include "structured_light/pattern_set.hpp"

namespace procam::cli {

namespace fs = std::filesystem;

// Writes one PNG per frame and DIR/sequence.json.
Result<void> writePatterns(const sl::PatternSet& set, const fs::path& dir);
Result<sl::PatternSet> readSequence(const fs::path& dir);

// Loads DIR/<frame name>.png for every frame (8 or 16 bit, as stored).
Result<std::vector<cv::Mat>> readCaptures(const sl::PatternSet& set, const fs::path& dir);

// Decodes the captures of DIR (the i-th of n, for the progress line) with `set`.
// kTooFewPoints when no camera pixel decodes (the projector was not in view).
Result<sl::Decoded> decodeDir(const sl::PatternSet& set, const std::string& dir, std::size_t i,
                              std::size_t n);

// 3-channel PFM: u, v, confidence; rows bottom to top, little-endian; -1 undecoded.
Result<void> writeCorrespondencePfm(const sl::Decoded& decoded, const fs::path& file);

using rig::cameraJson;
using rig::NamedCamera;
using rig::NamedProjector;
using rig::projectorJson;

Result<std::vector<NamedCamera>> readCameras(const fs::path& file);

Result<void> writeText(const fs::path& file, const std::string& text);
Result<nlohmann::json> readJson(const fs::path& file);

// Image files (png, jpg, jpeg, tif, tiff, bmp) of a directory, sorted by name.
Result<std::vector<fs::path>> listImages(const fs::path& dir);

}  // namespace procam::cli
