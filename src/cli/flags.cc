#include "liftoff/cli/flags.h"

#include <exception>

#include "liftoff/cli/commands.h"

namespace liftoff::cli {

FlagError::FlagError(Status status)
    : CLI::ParseError("FlagError", status.ToString(), ExitCodeFor(status.code())),
      status_(std::move(status)) {}

std::string Join(const std::vector<std::string>& parts, std::string_view separator) {
  std::string joined;
  for (size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) joined += separator;
    joined += parts[i];
  }
  return joined;
}

std::string OneOf(const std::vector<std::string>& words) {
  std::string joined;
  for (size_t i = 0; i < words.size(); ++i) {
    if (i > 0) joined += i + 1 == words.size() ? " or " : ", ";
    joined += words[i];
  }
  return joined;
}

std::optional<std::string> MessageNamingFlag(const std::string& message, const std::string& flag,
                                             const std::string& field, bool scaled) {
  // "engine.time_step_s" is also written "engine: time_step_s" (Status::WithContext)
  std::string with_context = field;
  for (size_t dot = with_context.find('.'); dot != std::string::npos;
       dot = with_context.find('.', dot)) {
    with_context.replace(dot, 1, ": ");
  }
  for (const std::string& name : {field, with_context}) {
    if (message.size() <= name.size() || message.compare(0, name.size(), name) != 0) continue;
    const char next = message[name.size()];
    if (next != ':' && next != '.') continue;
    if (scaled || next == '.') return flag + ": " + message;
    return flag + message.substr(name.size());
  }
  return std::nullopt;
}

CLI::Option* AddListOption(CLI::App& app, const std::string& flag, std::vector<std::string>& field,
                           const std::string& help) {
  return app.add_option(flag, field, help)
      ->delimiter(',')
      ->allow_extra_args(false)
      ->default_function([&field] { return Join(field, ","); })
      ->capture_default_str();
}

int RunCommandLine(CLI::App& app, const std::vector<Subcommand>& commands, int argc,
                   const char* const* argv, std::ostream& out, std::ostream& err) {
  try {
    app.parse(argc, argv);
  } catch (const FlagError& error) {
    return ReportError(error.status(), err);
  } catch (const CLI::ParseError& error) {
    const int code = app.exit(error, out, err);
    return code == 0 ? kExitOk : kExitUsage;
  }
  try {
    for (const Subcommand& command : commands) {
      if (command.app->parsed()) return command.run(out, err);
    }
  } catch (const std::exception& error) {
    err << "liftoff: internal error: " << error.what() << '\n';
    return kExitInternal;
  }
  return kExitUsage;
}

}  // namespace liftoff::cli
