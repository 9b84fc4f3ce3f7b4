// Tests for pipelines/geometry/intersect
