#include "slam/posegraph/robust_kernel.h"

#include <stdexcept>

namespace kestrel::slam {

KernelType parse_kernel_type(const std::string& name) {
  if (name == "none") return KernelType::kNone;
  if (name == "huber") return KernelType::kHuber;
  if (name == "cauchy") return KernelType::kCauchy;
  if (name == "dcs") return KernelType::kDcs;
  throw std::invalid_argument("unknown robust kernel '" + name +
                              "' (expected none, huber, cauchy or dcs)");
}

const char* kernel_type_name(KernelType type) {
  switch (type) {
    case KernelType::kNone: return "none";
    case KernelType::kHuber: return "huber";
    case KernelType::kCauchy: return "cauchy";
    case KernelType::kDcs: return "dcs";
  }
  return "?";
}

}  // namespace kestrel::slam
