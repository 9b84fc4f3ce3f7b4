// Tests for pipelines/geometry/plane_fit
