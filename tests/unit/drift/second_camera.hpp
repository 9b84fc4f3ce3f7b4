#pragma once
// A second fixed camera for wall_oblique, looking at the projector's image from the other
// side of the room (scene text to append): drift seen by two cameras.
namespace procam::drift {

inline constexpr const char* kSecondCamera = R"([[cameras]]
name = "cam2"
resolution = [1280, 960]
intrinsics = { fx = 1000.0, fy = 1000.0, cx = 639.1, cy = 481.0 }
distortion = { k1 = -0.05, k2 = 0.01, p1 = 0.0, p2 = 0.0, k3 = 0.0 }
pose = { position = [0.9, -0.6, 1.2], look_at = [-0.4, 3.0, 1.4] }
exposure = 1.0
gain = 1.0
bit_depth = 8
response_gamma = 1.0
read_noise_dn = 0.8
full_well_e = 12000.0
channels = 1
psf_sigma_px = 0.8
supersamples = 4

)";

}  // namespace procam::drift
