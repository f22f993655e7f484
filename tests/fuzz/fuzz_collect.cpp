// libFuzzer target: `rocklab collect DIR` on the files a sweep or study folder
// holds. Input: NUL-separated plan.json, runs/r0/results.json,
// runs/r1/results.json, logs/r0.exit, logs/r0.log. collect answers bad files
// with a message and an exit code; an exception, crash or hang is a finding.
#include <cstdint>
#include <sstream>

#include "fuzz_support.h"
#include "rocklab/experiments/sweep.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rocklab;
  const std::vector<std::string> parts = fuzz::splitInput(data, size, 5);
  const auto dir = fuzz::scratchDir() / "set";
  std::filesystem::remove_all(dir);
  for (const char* sub : {"runs/r0", "runs/r1", "logs"}) std::filesystem::create_directories(dir / sub);
  const char* const files[] = {"plan.json", "runs/r0/results.json", "runs/r1/results.json", "logs/r0.exit",
                               "logs/r0.log"};
  for (std::size_t k = 0; k < parts.size(); ++k) fuzz::writeFile(dir / files[k], parts[k]);
  std::ostringstream log;
  (void)experiments::collectSet(dir, log);
  return 0;
}
