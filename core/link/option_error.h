#ifndef ROVER_CORE_LINK_OPTION_ERROR_H_
#define ROVER_CORE_LINK_OPTION_ERROR_H_

// The one error of the team link's option checks (Validate()):
// std::invalid_argument "<Component>.<key>: expected <what>, found <value>".

#include <stdexcept>
#include <string>
#include <string_view>

namespace rover::link {

[[noreturn]] inline void FailOption(std::string_view component, std::string_view key,
                                    std::string_view expected, std::string_view found) {
  throw std::invalid_argument(std::string(component) + "." + std::string(key) + ": expected " +
                              std::string(expected) + ", found " + std::string(found));
}

}  // namespace rover::link

#endif  // ROVER_CORE_LINK_OPTION_ERROR_H_
