// The headless context: device choice and its errors, memory sub-allocation, buffers, and the
// validation layer actually reporting.
#include <gtest/gtest.h>

#include <cstdlib>
#include <numeric>
#include <optional>
#include <string>

#include "fluidcast/gpu/memory.h"
#include "fluidcast/gpu/transfer.h"
#include "fluidcast/gpu/vk_check.h"
#include "gpu_test_support.h"

namespace fluidcast::gpu {
namespace {

using fluidcast::testing::GpuTest;

class GpuContextTest : public GpuTest {};

TEST_F(GpuContextTest, ChoosesAUsableListedDevice) {
  const auto devices = list_devices();
  ASSERT_FALSE(devices.empty());
  const DeviceInfo& chosen = context().info();
  ASSERT_LT(chosen.index, devices.size());
  EXPECT_EQ(devices[chosen.index].name, chosen.name);
  EXPECT_TRUE(chosen.rejected_because.empty());
}

TEST_F(GpuContextTest, AMissingDeviceIsAnErrorListingTheDevices) {
  ContextOptions options;
  options.device_index = 99;
  options.validation = false;
  try {
    Context missing(options);
    ADD_FAILURE() << "no error";
  } catch (const GpuUnavailable& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("there is no Vulkan device 99"), std::string::npos) << what;
    EXPECT_NE(what.find(context().info().name), std::string::npos) << what;
  }
}

TEST_F(GpuContextTest, DeviceFromTheEnvironmentMustBeAnIndex) {
  ::setenv("FLUIDCAST_DEVICE", "first", 1);
  EXPECT_THROW(options_from_environment(), GpuUnavailable);
  ::setenv("FLUIDCAST_DEVICE", "4294967296", 1);  // it wrapped to device 0
  EXPECT_THROW(options_from_environment(), GpuUnavailable);
  ::setenv("FLUIDCAST_DEVICE", "0", 1);
  EXPECT_EQ(options_from_environment().device_index, 0u);
  ::unsetenv("FLUIDCAST_DEVICE");
  EXPECT_FALSE(options_from_environment().device_index.has_value());
}

TEST_F(GpuContextTest, BuffersRoundTripThroughTheDevice) {
  std::vector<std::uint32_t> values(100'000);
  std::iota(values.begin(), values.end(), 7u);
  const Buffer buffer(context(), values.size() * 4, MemoryDomain::device);
  upload<std::uint32_t>(context(), buffer, values);
  EXPECT_EQ(download<std::uint32_t>(context(), buffer, values.size()), values);
  EXPECT_NE(buffer.address(), 0u);
  EXPECT_THROW(upload<std::uint32_t>(context(), buffer, std::vector<std::uint32_t>(100'001)),
               std::out_of_range);
}

// Several ranges of several buffers in one submission, each where it belongs; a range beyond its
// buffer is refused before anything moves.
TEST_F(GpuContextTest, SeveralRangesTravelInOneSubmission) {
  const Buffer a(context(), 64, MemoryDomain::device), b(context(), 32, MemoryDomain::device);
  const std::vector<std::uint32_t> first{1, 2, 3, 4}, second{5, 6}, third{7, 8, 9};
  const std::uint64_t before = context().last_submitted();
  const Upload uploads[] = {{a, std::as_bytes(std::span(first))},
                            {b, std::as_bytes(std::span(second)), 8},
                            {a, {}, 0},
                            {a, std::as_bytes(std::span(third)), 40}};
  upload_all(context(), uploads);
  EXPECT_EQ(context().last_submitted(), before + 1);
  std::vector<std::uint32_t> got_a(16), got_b(2);
  const Download downloads[] = {{a, std::as_writable_bytes(std::span(got_a))},
                                {b, std::as_writable_bytes(std::span(got_b)), 8}};
  download_all(context(), downloads);
  EXPECT_EQ(context().last_submitted(), before + 2);
  EXPECT_EQ(std::vector<std::uint32_t>(got_a.begin(), got_a.begin() + 4), first);
  EXPECT_EQ(std::vector<std::uint32_t>(got_a.begin() + 10, got_a.begin() + 13), third);
  EXPECT_EQ(got_b, second);
  const std::vector<std::uint32_t> ones(4, 1);
  const Upload too_far[] = {{a, std::as_bytes(std::span(ones))},
                            {b, std::as_bytes(std::span(ones)), 24}};
  EXPECT_THROW(upload_all(context(), too_far), std::out_of_range);
  EXPECT_EQ(context().last_submitted(), before + 2);
  EXPECT_EQ(download<std::uint32_t>(context(), a, 4), first);
}

TEST_F(GpuContextTest, SmallBuffersShareABlockAndLargeOnesGetTheirOwn) {
  MemoryAllocator& memory = context().memory();
  const std::size_t blocks_before = memory.block_count();
  {
    std::vector<Buffer> small;
    for (int k = 0; k < 200; ++k) small.emplace_back(context(), 4096, MemoryDomain::device);
    EXPECT_LE(memory.block_count(), blocks_before + 1);
    const std::size_t with_small = memory.block_count();
    {
      const Buffer large(context(), MemoryAllocator::kBlockSize + 1, MemoryDomain::device);
      EXPECT_EQ(memory.block_count(), with_small + 1);
      EXPECT_GE(large.size(), MemoryAllocator::kBlockSize + 1);
    }
    EXPECT_EQ(memory.block_count(), with_small);  // a block of its own goes back at once
  }
  // At most one empty standard block per memory type stays.
  EXPECT_LE(memory.block_count(), blocks_before + 1);
}

TEST_F(GpuContextTest, AMemoryLimitRefusesWhatWouldPassItAndCountsWhatIsGivenBack) {
  constexpr VkDeviceSize kBlock = MemoryAllocator::kBlockSize;
  ContextOptions options = options_from_environment();
  options.memory_limit_bytes = 3 * kBlock;
  options.log = [](const std::string&) {};
  Context limited(options);
  EXPECT_LE(limited.info().device_local_bytes, 3 * kBlock);  // what budgets are drawn from
  std::optional<Buffer> large(std::in_place, limited, 2 * kBlock, MemoryDomain::device);
  const Buffer small(limited, 4096, MemoryDomain::device);  // a standard block: the limit's last
  try {
    const Buffer over(limited, kBlock + 1, MemoryDomain::device);
    ADD_FAILURE() << "a fourth block's worth was allocated";
  } catch (const VulkanError& e) {
    EXPECT_TRUE(e.out_of_memory());
    EXPECT_NE(std::string(e.what()).find("limit of 192 MiB"), std::string::npos) << e.what();
  }
  {
    const Buffer within(limited, 4096, MemoryDomain::device);  // in the standard block's room
  }
  large.reset();  // a block of its own: given back at once
  EXPECT_NO_THROW(Buffer(limited, kBlock + 1, MemoryDomain::device));
  {
    const Buffer first(limited, 40 << 20, MemoryDomain::device);   // beside `small`
    const Buffer second(limited, 40 << 20, MemoryDomain::device);  // in a second standard block
  }
  ASSERT_EQ(limited.memory().block_count(), 2u);  // that one stays, empty, for the next buffers
  EXPECT_EQ(limited.memory().block_bytes(), 2 * kBlock);
  // The spare makes room for what needs it more.
  EXPECT_NO_THROW(Buffer(limited, 2 * kBlock, MemoryDomain::device));
  EXPECT_TRUE(limited.validation_errors().empty());
}

// One piece larger than the device allocates at once is refused before the driver sees it, as
// the out-of-memory it amounts to (a request that fails alone).
TEST_F(GpuContextTest, MoreThanTheDeviceAllocatesInOnePieceIsOutOfMemory) {
  VkPhysicalDeviceMaintenance3Properties maintenance{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
  VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2,
                                         &maintenance};
  vkGetPhysicalDeviceProperties2(context().physical_device(), &properties);
  EXPECT_EQ(context().info().largest_allocation_bytes, maintenance.maxMemoryAllocationSize);
  VkMemoryRequirements requirements{};
  requirements.size = maintenance.maxMemoryAllocationSize + 1;
  requirements.alignment = 256;
  requirements.memoryTypeBits = ~0u;
  try {
    context().memory().allocate(requirements, MemoryDomain::device);
    ADD_FAILURE() << "an allocation past maxMemoryAllocationSize was made";
  } catch (const VulkanError& e) {
    EXPECT_TRUE(e.out_of_memory());
    EXPECT_NE(std::string(e.what()).find("in one piece"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(context().validation_errors().empty());
}

// Staging buffers come and go with every upload and snapshot: their memory must not.
TEST_F(GpuContextTest, ShortLivedBuffersDoNotAllocateMemoryEachTime) {
  MemoryAllocator& memory = context().memory();
  const std::uint64_t before = memory.allocations_made();
  for (int k = 0; k < 20; ++k) {
    const Buffer staging(context(), 4096, MemoryDomain::upload);
    staging.mapped<std::uint32_t>()[0] = 7u;
  }
  EXPECT_LE(memory.allocations_made(), before + 1);
}

TEST_F(GpuContextTest, ValidationErrorsAreCollected) {
  if (!context().validation_enabled()) GTEST_SKIP() << "vulkan-validationlayers is not installed";
  const std::size_t before = context().validation_errors().size();
  // A buffer of size 0 breaks a valid-usage rule (VUID-VkBufferCreateInfo-size-00912).
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = 0;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
  VkBuffer buffer = VK_NULL_HANDLE;
  const VkResult result = vkCreateBuffer(context().device(), &info, nullptr, &buffer);
  if (result == VK_SUCCESS && buffer != VK_NULL_HANDLE)
    vkDestroyBuffer(context().device(), buffer, nullptr);
  const auto errors = context().validation_errors();
  ASSERT_GT(errors.size(), before);
  EXPECT_NE(errors.back().find("00912"), std::string::npos) << errors.back();
  forget_validation_messages();  // this test made them on purpose
}

TEST_F(GpuContextTest, SubmissionsAreNumberedAndTheTimelineFollowsThem) {
  const std::uint64_t before = context().last_submitted();
  const Buffer buffer(context(), 256, MemoryDomain::device);
  upload<std::uint32_t>(context(), buffer, std::vector<std::uint32_t>(64, 7));
  const std::uint64_t serial = context().last_submitted();
  EXPECT_EQ(serial, before + 1);
  EXPECT_GE(context().last_finished(), serial);  // upload waits for its submission
  EXPECT_TRUE(context().wait_for(serial, std::chrono::milliseconds(0)));
  // A serial not yet submitted is not finished: the wait gives up at its timeout.
  EXPECT_FALSE(context().wait_for(serial + 1, std::chrono::milliseconds(1)));
}

// Counts destructions, to see when the context lets go of what was retired.
struct Watched {
  explicit Watched(std::shared_ptr<int> count) : destroyed(std::move(count)) {}
  Watched(Watched&&) = default;
  ~Watched() {
    if (destroyed) ++*destroyed;
  }
  std::shared_ptr<int> destroyed;
};

TEST_F(GpuContextTest, RetiredObjectsGoOnASubmissionAfterTheirLastHasFinished) {
  auto destroyed = std::make_shared<int>(0);
  const std::size_t before = context().retired_count();
  context().retire(Watched(destroyed));
  context().retire(Buffer(context(), 1024, MemoryDomain::device));
  EXPECT_EQ(*destroyed, 0);  // kept until a later submission finds its work finished
  EXPECT_EQ(context().retired_count(), before + 2);
  const Buffer buffer(context(), 16, MemoryDomain::device);
  upload<std::uint32_t>(context(), buffer, std::vector<std::uint32_t>(4, 1));
  EXPECT_EQ(*destroyed, 1);
  EXPECT_EQ(context().retired_count(), 0u);
}

TEST(VulkanCheck, NamesTheCallTheResultAndThePlace) {
  try {
    FLUIDCAST_VK_CHECK(VK_ERROR_OUT_OF_DEVICE_MEMORY);
    ADD_FAILURE() << "no throw";
  } catch (const VulkanError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("VK_ERROR_OUT_OF_DEVICE_MEMORY"), std::string::npos) << what;
    EXPECT_NE(what.find("gpu_context_test.cpp"), std::string::npos) << what;
  }
  EXPECT_THROW(FLUIDCAST_VK_CHECK(VK_ERROR_DEVICE_LOST), DeviceLostError);
}

}  // namespace
}  // namespace fluidcast::gpu
