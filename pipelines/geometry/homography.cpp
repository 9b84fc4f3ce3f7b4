#include "geometry/homography.hpp"
