#include "geometry/rigid.hpp"
