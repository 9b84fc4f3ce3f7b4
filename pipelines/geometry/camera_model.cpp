#include "geometry/camera_model.hpp"
