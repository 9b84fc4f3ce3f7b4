#pragma once
// A fixed camera that moved, told apart from a moved projector by a second camera that
// still sees the projector's content where the rig model puts it: the camera's pose is
// fitted again to the content it sees (PnP from its old pose). The projector is right, so
// the content drawn at framebuffer pixel p is on the surface where the rig model puts p
// (the plane collineation, or p's ray meeting the mesh); the moved camera saw it at the
// camera pixel the drift check's map gives the grid point where it was found. Pure.
#include <opencv2/core.hpp>

#include "core/error.hpp"
#include "geometry/plane_homography.hpp"
#include "misregistration.hpp"
#include "projector_camera_map.hpp"
#include "rig/rig_model.hpp"

namespace procam::drift {

struct CameraCorrection {
  rig::RigCamera camera;   // the corrected entry (same name, K, distortion)
  double pose_rms_px = 0;  // the new pose's reprojection RMS, camera pixels
  int tiles = 0;
};

// `tile`: the projector's collineation with the plane the check used; `map` and `grid`:
// the check's (projectorCameraMap for the camera before it moved). kTooFewPoints under 8
// inlier tiles; kIllConditioned when the new pose fits them worse than 1 camera px RMS;
// kInvalidInput for a camera without a pose or non-finite input.
Result<CameraCorrection> correctCamera(const rig::RigCamera& before,
                                       const geom::PlaneHomography& tile,
                                       const Misregistration& drift, const cv::Mat& map,
                                       const WorkGrid& grid);
// `surface`: where the rig model says the projector's pixels light the surface (a mesh's
// included); errors as above, and kInvalidInput without one.
Result<CameraCorrection> correctCamera(const rig::RigCamera& before, const LitSurface& surface,
                                       const Misregistration& drift, const cv::Mat& map,
                                       const WorkGrid& grid);

}  // namespace procam::drift
