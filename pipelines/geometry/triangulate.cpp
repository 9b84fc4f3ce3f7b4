#include "geometry/triangulate.hpp"
