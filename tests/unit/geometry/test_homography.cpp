// Tests for pipelines/geometry/homography
