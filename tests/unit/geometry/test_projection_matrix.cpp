// Tests for pipelines/geometry/projection_matrix
