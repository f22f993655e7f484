// rocklab executable: all logic lives in rocklab_experiments (testable in-process).
#include "rocklab/experiments/cli.h"

int main(int argc, char** argv) { return rocklab::experiments::runCli(argc, argv); }
