// `liftoff ports`: the machine's serial ports.
#include "liftoff/cli/capture_commands.h"

#include <memory>
#include <ostream>

#include "cli_common.h"
#include "liftoff/capture/serial_port.h"

namespace liftoff::cli {

int RunPorts(const PortsCommand&, std::ostream& out, std::ostream& err) {
  auto ports = capture::ListPorts();
  if (!ports.ok()) return ReportError(ports.status(), err);
  out << capture::FormatPortList(*ports);
  return kExitOk;
}

Subcommand AddPortsCommand(Command& parent) {
  auto command = std::make_shared<PortsCommand>();
  Command* app = parent.AddSubcommand("ports", "List the serial ports of this machine");
  return RunsWith(app, command, RunPorts);
}

}  // namespace liftoff::cli
