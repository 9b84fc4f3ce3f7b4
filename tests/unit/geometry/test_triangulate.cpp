// Tests for pipelines/geometry/triangulate
