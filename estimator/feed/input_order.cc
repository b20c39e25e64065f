#include "estimator/feed/input_order.h"

#include <algorithm>
#include <type_traits>
#include <variant>

namespace rover::estimator {

int InputRank(const EskfInput& input) {
  return std::visit(
      [](const auto& m) {
        using T = std::decay_t<decltype(m)>;
        if constexpr (std::is_same_v<T, ImuMeasurement>) return 0;
        if constexpr (std::is_same_v<T, WheelSpeedMeasurement>) return 1;
        if constexpr (std::is_same_v<T, CloneTrigger>) return 2;
        if constexpr (std::is_same_v<T, RelativePoseMeasurement>) return 3;
        if constexpr (std::is_same_v<T, FrameSwitchRequest>) return 4;
        if constexpr (std::is_same_v<T, PoseReportRequest>) return 5;
      },
      input);
}

bool InputBefore(const EskfInput& a, const EskfInput& b) {
  const Time ta = StampOf(a), tb = StampOf(b);
  return ta < tb || (ta == tb && InputRank(a) < InputRank(b));
}

void SortInputs(std::vector<EskfInput>* inputs) {
  std::stable_sort(inputs->begin(), inputs->end(), InputBefore);
}

}  // namespace rover::estimator
