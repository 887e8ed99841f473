// liftoff: the command line. Each command is a file of src/cli/ (its flags bound to its
// options struct, its Run function); liftoff/cli/command_table.h lists them.
#include <iostream>

#include "liftoff/cli/command_table.h"

int main(int argc, char** argv) {
  return liftoff::cli::RunLiftoff(argc, argv, std::cout, std::cerr);
}
