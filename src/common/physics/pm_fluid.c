/* pm_fluid: names of the equations of state. */
#include "pm_fluid.h"

const char *pm_eos_name(pm_eos eos) {
  switch (eos) {
  case PM_EOS_NONE: return "none";
  case PM_EOS_IDEAL_GAS: return "ideal-gas";
  case PM_EOS_STIFFENED_GAS: return "stiffened-gas";
  }
  return "?";
}
