#include "geometry/intersect.hpp"
