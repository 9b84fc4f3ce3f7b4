#include "geometry/projection_matrix.hpp"
