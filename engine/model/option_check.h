#pragma once
// The one convention for every Options struct's check(): it returns nothing and throws an
// OptionError naming the first option out of range, its value and the range it must lie in.
// Nested structs prefix their member's name (within), so the refiner's error names the path the
// command line's option table maps back to a flag.

#include <sstream>
#include <string>

#include "engine/model/error.h"

namespace mvflow {

//! An option value outside its valid range. what() reads "option NAME = VALUE is out of range:
//! expected EXPECTED" (e.g. "option smoothing.lambda_dt = 1.5 is out of range: expected in (0, 1)").
class OptionError : public InputError {
 public:
  //! \param option the member's name (a path for nested structs); \param expected what the value
  //! must be, completing "expected ..." ("in (0, 10]", ">= 1", "0 or >= 2").
  OptionError(std::string option, std::string value, std::string expected);

  const std::string& option() const { return option_; }
  const std::string& value() const { return value_; }
  const std::string& expected() const { return expected_; }
  //! The same error for the member \p member of an enclosing struct ("smoothing" + "lambda_dt").
  OptionError within(const std::string& member) const;

 private:
  std::string option_, value_, expected_;
};

//! Throws OptionError(\p option, \p value printed, \p expected) unless \p ok. Write \p ok so that
//! NaN fails it (x > 0, not !(x <= 0)).
template <typename T>
void require_option(bool ok, const char* option, const T& value, const std::string& expected) {
  if (ok) return;
  std::ostringstream text;
  text << std::boolalpha << value;
  throw OptionError(option, text.str(), expected);
}

//! Runs \p nested.check(), naming a failing option as a member of \p member.
template <typename Options>
void check_member(const Options& nested, const char* member) {
  try {
    nested.check();
  } catch (const OptionError& e) {
    throw e.within(member);
  }
}

}  // namespace mvflow
