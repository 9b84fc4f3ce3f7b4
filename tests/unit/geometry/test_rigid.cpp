// Tests for pipelines/geometry/rigid
