// Tests for pipelines/geometry/camera_model
