#include "engine/model/option_check.h"

#include <utility>

namespace mvflow {

OptionError::OptionError(std::string option, std::string value, std::string expected)
    : InputError("option " + option + " = " + value + " is out of range: expected " + expected),
      option_(std::move(option)),
      value_(std::move(value)),
      expected_(std::move(expected)) {}

OptionError OptionError::within(const std::string& member) const {
  return OptionError(member + "." + option_, value_, expected_);
}

}  // namespace mvflow
