// Stress: homography, projection matrix, camera model
