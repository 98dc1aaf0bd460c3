// The message of an InputError a test expects: one helper for every room's tests.
#pragma once

#include <gtest/gtest.h>

#include <string>

#include "renderer/error.hpp"

namespace sb::test {

/// Runs `f`, which is expected to throw InputError, and returns its message; a test failure (and
/// "") when it throws none.
template <class F>
std::string input_error(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError thrown";
  return {};
}

}  // namespace sb::test
