// The one place that includes mrcal's C headers. mrcal 2.2 ships them without
// extern "C" guards, so a C++ translation unit must wrap them.
#pragma once

extern "C" {
#include <mrcal/mrcal.h>
}
