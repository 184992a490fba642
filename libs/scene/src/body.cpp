#include "fahr/scene/body.h"

namespace fahr::scene {

double metres_per_unit(LengthUnit unit) {
  switch (unit) {
    case LengthUnit::kMetre:
      return 1.0;
    case LengthUnit::kCentimetre:
      return 0.01;
    case LengthUnit::kMillimetre:
      return 0.001;
  }
  return 1.0;  // unreachable: every enumerator is handled above
}

}  // namespace fahr::scene
