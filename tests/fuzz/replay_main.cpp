// A fuzz target's driver for the everyday build (GCC, no libFuzzer): every input of the target's
// corpus (its regression inputs and seeds), then random mutations of them for a bounded time.
// Not coverage-guided — that is `make fuzz` (clang's libFuzzer) — but it runs in `make test` and
// keeps every input that once crashed a target from crashing it again.
//   <target>_replay CORPUS_DIR [--seconds S] [--seed N]
// An exception escaping the target, or a crash, fails it; the input is written to
// fuzz-failure-<target> first.
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {

using Input = std::vector<std::uint8_t>;

void run(const Input& input, const std::string& target) {
  {  // written before the run: a crash leaves it behind
    std::ofstream out("fuzz-failure-" + target, std::ios::binary);
    out.write(reinterpret_cast<const char*>(input.data()), std::streamsize(input.size()));
  }
  try {
    LLVMFuzzerTestOneInput(input.data(), input.size());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s: an input (%zu bytes, in fuzz-failure-%s) escaped with: %s\n",
                 target.c_str(), input.size(), target.c_str(), e.what());
    std::exit(1);
  }
}

Input mutate(Input input, std::mt19937_64& random) {
  const int edits = 1 + int(random() % 8);
  for (int k = 0; k < edits; ++k) {
    const std::size_t at = input.empty() ? 0 : random() % input.size();
    switch (random() % 5) {
      case 0:  // flip a bit
        if (!input.empty()) input[at] ^= std::uint8_t(1u << (random() % 8));
        break;
      case 1:  // a random byte
        if (!input.empty()) input[at] = std::uint8_t(random());
        break;
      case 2:  // insert bytes
        input.insert(input.begin() + std::ptrdiff_t(at), 1 + random() % 16, std::uint8_t(random()));
        break;
      case 3:  // cut bytes
        if (!input.empty()) {
          input.erase(
              input.begin() + std::ptrdiff_t(at),
              input.begin() + std::ptrdiff_t(std::min(input.size(), at + 1 + random() % 16)));
        }
        break;
      case 4:  // an interesting value: lengths and varints at their edges
        if (!input.empty())
          input[at] = std::uint8_t(std::array<int, 6>{0, 1, 0x7f, 0x80, 0xfe, 0xff}[random() % 6]);
        break;
    }
  }
  return input;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR [--seconds S] [--seed N]\n", argv[0]);
    return 2;
  }
  const std::string target = std::filesystem::path(argv[0]).filename().string();
  double seconds = 2.0;
  std::uint64_t seed = std::random_device{}();
  for (int k = 2; k + 1 < argc; k += 2) {
    const std::string flag = argv[k];
    if (flag == "--seconds")
      seconds = std::stod(argv[k + 1]);
    else if (flag == "--seed")
      seed = std::stoull(argv[k + 1]);
  }
  std::vector<Input> corpus;
  for (const auto& entry : std::filesystem::directory_iterator(argv[1])) {
    std::ifstream in(entry.path(), std::ios::binary);
    corpus.emplace_back(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    run(corpus.back(), target);
  }
  if (corpus.empty()) corpus.emplace_back();
  std::mt19937_64 random(seed);
  std::size_t runs = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    run(mutate(corpus[random() % corpus.size()], random), target);
    ++runs;
  }
  std::filesystem::remove("fuzz-failure-" + target);
  std::printf("%s: %zu corpus inputs and %zu mutations (seed %llu) passed\n", target.c_str(),
              corpus.size(), runs, static_cast<unsigned long long>(seed));
  return 0;
}
