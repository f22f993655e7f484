// Replays inputs through a fuzz target without libFuzzer: each argument is a
// file or a folder of files (tests/fuzz/corpus/TARGET, regressions/TARGET).
// The CI suite runs every target over its seeds and the inputs of fixed
// findings this way, in the ordinary build; a crash or an escaped exception
// fails the test as it failed the fuzzer.
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <iostream>
#include <vector>

#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> inputs;
  for (int k = 1; k < argc; ++k) {
    const std::filesystem::path p(argv[k]);
    if (std::filesystem::is_directory(p)) {
      for (const auto& e : std::filesystem::directory_iterator(p))
        if (e.is_regular_file()) inputs.push_back(e.path());
    } else if (std::filesystem::exists(p)) {
      inputs.push_back(p);
    }
  }
  std::sort(inputs.begin(), inputs.end());
  for (const auto& input : inputs) {
    const std::string bytes = rocklab::fuzz::readFile(input);
    std::cerr << "replay " << input.string() << "\n";
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::cerr << "replayed " << inputs.size() << " inputs\n";
  std::filesystem::remove_all(rocklab::fuzz::scratchDir());
  return inputs.empty() ? 1 : 0;
}
