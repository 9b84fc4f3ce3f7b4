#include "geometry/plane_fit.hpp"
