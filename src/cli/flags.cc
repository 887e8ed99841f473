// The only file that includes CLI11 (see flags.h).
#include "liftoff/cli/flags.h"

#include <cstdint>
#include <exception>
#include <filesystem>

#include "liftoff/cli/cli11.h"
#include "liftoff/cli/commands.h"

namespace liftoff::cli {

FlagError::FlagError(Status status)
    : std::runtime_error(status.ToString()), status_(std::move(status)) {}

// ---------------------------------------------------------------------------------------
// Flag

Flag* Flag::Required() {
  option_->required();
  return this;
}

Flag* Flag::ShowDefault() {
  option_->capture_default_str();
  return this;
}

Flag* Flag::ShowDefaultFrom(std::function<std::string()> text) {
  option_->default_function(std::move(text))->capture_default_str();
  return this;
}

Flag* Flag::Needs(Flag* other) {
  option_->needs(other->option_);
  return this;
}

Flag* Flag::Excludes(Flag* other) {
  option_->excludes(other->option_);
  return this;
}

Flag* Flag::TypeName(const std::string& name) {
  option_->type_name(name);
  return this;
}

Flag* Flag::CommaSeparated() {
  option_->delimiter(',')->allow_extra_args(false);
  return this;
}

Flag* Flag::OneOrMore() {
  option_->expected(1, -1);
  return this;
}

// ---------------------------------------------------------------------------------------
// Command

Command::Command(CLI::App* app) : app_(app) {}

Command::~Command() = default;

Command* Command::AddSubcommand(const std::string& name, const std::string& help) {
  subcommands_.push_back(std::make_unique<Command>(app_->add_subcommand(name, help)));
  return subcommands_.back().get();
}

void Command::RequireSubcommand() { app_->require_subcommand(1); }

template <typename Value>
Flag* Command::AddOption(const std::string& name, Value& field, const std::string& help) {
  return Keep(app_->add_option(name, field, help));
}

template <typename Value>
Flag* Command::AddOptionFunction(const std::string& name, std::function<void(const Value&)> parse,
                                 const std::string& help) {
  return Keep(app_->add_option_function<Value>(name, std::move(parse), help));
}

Flag* Command::AddSwitch(const std::string& name, bool& field, const std::string& help) {
  return Keep(app_->add_flag(name, field, help));
}

bool Command::Parsed() const { return app_->parsed(); }

Flag* Command::Keep(CLI::Option* option) {
  flags_.push_back(std::make_unique<Flag>(option));
  return flags_.back().get();
}

// the value types the command files bind: AddOption ...
template Flag* Command::AddOption(const std::string&, std::string&, const std::string&);
template Flag* Command::AddOption(const std::string&, double&, const std::string&);
template Flag* Command::AddOption(const std::string&, int&, const std::string&);
template Flag* Command::AddOption(const std::string&, int64_t&, const std::string&);
template Flag* Command::AddOption(const std::string&, uint64_t&, const std::string&);
template Flag* Command::AddOption(const std::string&, std::optional<double>&, const std::string&);
template Flag* Command::AddOption(const std::string&, std::vector<std::string>&,
                                  const std::string&);
template Flag* Command::AddOption(const std::string&, std::filesystem::path&, const std::string&);
template Flag* Command::AddOption(const std::string&, std::vector<std::filesystem::path>&,
                                  const std::string&);
template Flag* Command::AddOption(const std::string&, std::vector<double>&, const std::string&);
// ... and AddOptionFunction
template Flag* Command::AddOptionFunction(const std::string&,
                                          std::function<void(const std::string&)>,
                                          const std::string&);
template Flag* Command::AddOptionFunction(const std::string&, std::function<void(const double&)>,
                                          const std::string&);
template Flag* Command::AddOptionFunction(const std::string&, std::function<void(const int&)>,
                                          const std::string&);
template Flag* Command::AddOptionFunction(const std::string&,
                                          std::function<void(const std::vector<double>&)>,
                                          const std::string&);

// ---------------------------------------------------------------------------------------
// helpers

std::string Join(const std::vector<std::string>& parts, std::string_view separator) {
  std::string joined;
  for (size_t i = 0; i < parts.size(); ++i) {
    if (i > 0) joined += separator;
    joined += parts[i];
  }
  return joined;
}

std::string JoinNumbers(const std::vector<double>& values, std::string_view separator) {
  std::vector<std::string> parts;
  for (double value : values) parts.push_back(FormatNumber(value));
  return Join(parts, separator);
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

Flag* AddListOption(Command& app, const std::string& flag, std::vector<std::string>& field,
                    const std::string& help) {
  return app.AddOption(flag, field, help)->CommaSeparated()->ShowDefaultFrom([&field] {
    return Join(field, ",");
  });
}

int RunCommandLine(const std::string& description, const std::string& version,
                   const CommandTable& table, int argc, const char* const* argv, std::ostream& out,
                   std::ostream& err) {
  CLI::App app{description};
  app.set_version_flag("--version", version);
  Command root(&app);
  const std::vector<Subcommand> commands = table(root);
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
      if (command.app->Parsed()) return command.run(out, err);
    }
  } catch (const std::exception& error) {
    err << "liftoff: internal error: " << error.what() << '\n';
    return kExitInternal;
  }
  return kExitUsage;
}

}  // namespace liftoff::cli
