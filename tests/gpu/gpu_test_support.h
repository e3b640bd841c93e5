// Shared by the GPU tests: one Vulkan context per test program, with the validation layer on when
// it is installed; a validation message during a test fails that test.
#pragma once

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <variant>

#include "fluidcast/codec/image.h"
#include "fluidcast/gpu/context.h"

namespace fluidcast::testing {

inline gpu::Context& test_context() {
  static gpu::Context context([] {
    gpu::ContextOptions options = gpu::options_from_environment();
    options.validation = true;
    return options;
  }());
  return context;
}

// A frame read back as RGBA, the renderer's default format.
inline codec::ImageRgba rgba(codec::Image image) {
  return std::get<codec::ImageRgba>(std::move(image));
}

class GpuTest : public ::testing::Test {
 protected:
  void SetUp() override { messages_before_ = test_context().validation_errors().size(); }
  void TearDown() override {
    const auto messages = test_context().validation_errors();
    std::string text;
    for (std::size_t k = messages_before_; k < messages.size(); ++k) text += messages[k] + "\n";
    EXPECT_EQ(messages.size(), messages_before_) << "validation messages:\n" << text;
  }
  gpu::Context& context() { return test_context(); }
  // For a test that provokes validation messages on purpose.
  void forget_validation_messages() {
    messages_before_ = test_context().validation_errors().size();
  }

 private:
  std::size_t messages_before_ = 0;
};

}  // namespace fluidcast::testing
