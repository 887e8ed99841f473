// Command-line flags bound once to the fields of option structs (COLMAP's OptionManager
// is the model). A table of FieldFlag lines, one per field, is the only place a flag is
// named: it adds the flag to a CLI11 command bound to the field (its help shows the
// field's value at that moment, i.e. the struct's default), writes the field back as the
// flag would be given (DescribeChanged), and names the flag in the struct's Validate()
// messages (NameFlagIn). Validate() stays the only range check.
//
// CLI11 stays behind Command and Flag: only src/cli/flags.cc includes it, so the command
// files do not each compile the parser's templates again (a build-time cost, not a style
// rule: CLI11 2.1 is header-only).
//
//   using O = sim::ExperimentOptions;
//   NumberFlag<O>("--threshold-mm", LIFTOFF_FIELD(liftoff_threshold_m), kMillimetresForMetres,
//                 "Liftoff: height above the reference, mm"),
#pragma once

#include <functional>
#include <memory>
#include <numbers>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

#include "liftoff/core/json.h"
#include "liftoff/core/status.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace liftoff::cli {

/// A bad value for a flag that no option struct can hold (a word outside the flag's
/// choices, a list of the wrong length), thrown while parsing: RunCommandLine reports its
/// status like a Run function's failure (the class's exit code, docs/cli.md).
class FlagError : public std::runtime_error {
 public:
  explicit FlagError(Status status);
  const Status& status() const { return status_; }

 private:
  Status status_;
};

/// One flag or positional argument of a Command (a CLI11 option). Its methods return
/// the flag itself, to chain: app->AddOption(...)->Required().
class Flag {
 public:
  explicit Flag(CLI::Option* option) : option_(option) {}
  /// The command line must give it.
  Flag* Required();
  /// Help shows the bound field's value at this moment (the struct's default).
  Flag* ShowDefault();
  /// Help shows `text()` now (the bound field's value, as the flag would write it).
  Flag* ShowDefaultFrom(std::function<std::string()> text);
  /// Given only together with `other`.
  Flag* Needs(Flag* other);
  /// Never given together with `other`.
  Flag* Excludes(Flag* other);
  /// The value's name in help ("A|B").
  Flag* TypeName(const std::string& name);
  /// A list in one argument, comma-separated ("1,2,3").
  Flag* CommaSeparated();
  /// Takes one value or more (a flag: the arguments after it, up to the next flag).
  Flag* OneOrMore();

 private:
  CLI::Option* option_;
};

/// A command of the command line (a CLI11 app): its flags and subcommands, owned here.
/// `Value` is one of the types src/cli/flags.cc instantiates, listed there for each
/// function (another is a link error).
class Command {
 public:
  /// Wraps `app` (not owned; it must outlive this).
  explicit Command(CLI::App* app);
  ~Command();
  Command(const Command&) = delete;
  Command& operator=(const Command&) = delete;

  /// A subcommand, owned by this command.
  Command* AddSubcommand(const std::string& name, const std::string& help);
  /// One subcommand must be given.
  void RequireSubcommand();
  /// A flag ("--name,-n") or positional ("name") writing `field` (which must outlive this).
  template <typename Value>
  Flag* AddOption(const std::string& name, Value& field, const std::string& help);
  /// A flag calling `parse` with its value.
  template <typename Value>
  Flag* AddOptionFunction(const std::string& name, std::function<void(const Value&)> parse,
                          const std::string& help);
  /// A flag without a value: given means true.
  Flag* AddSwitch(const std::string& name, bool& field, const std::string& help);
  /// Whether the command line chose this command.
  bool Parsed() const;
  /// The CLI11 app, for tests that walk its options (they include liftoff/cli/cli11.h).
  CLI::App* cli_app() const { return app_; }

 private:
  Flag* Keep(CLI::Option* option);

  CLI::App* app_;
  std::vector<std::unique_ptr<Command>> subcommands_;
  std::vector<std::unique_ptr<Flag>> flags_;
};

/// `parts` with `separator` between them: Join({"A", "C"}, ",") is "A,C".
std::string Join(const std::vector<std::string>& parts, std::string_view separator);

/// `values` as FormatNumber writes them, `separator` between: "0.5,1,2".
std::string JoinNumbers(const std::vector<double>& values, std::string_view separator);

/// "a or b", "a, b or c": the words a flag takes, for messages and help.
std::string OneOf(const std::vector<std::string>& words);

/// Units of a flag per unit of its field: the flag reads field * flag_per_field.
struct FlagUnit {
  double flag_per_field = 1.0;
};
inline constexpr FlagUnit kSameUnit{1.0};
inline constexpr FlagUnit kMillimetresForMetres{1e3};
inline constexpr FlagUnit kDegreesForRadians{180.0 / std::numbers::pi};
inline constexpr FlagUnit kMillisecondsForSeconds{1e3};

/// One flag bound to one field of `Options`.
template <typename Options>
struct FieldFlag {
  /// "--ramp-deg".
  std::string flag;
  /// The field's name as Validate() writes it ("ramp_angle_rad", "engine.time_step_s").
  std::string field;
  /// Whether the flag's unit differs from the field's.
  bool scaled = false;
  /// A flag without a value (given: on).
  bool is_switch = false;
  /// Adds the flag to `app`, bound to the field of `options` (which must outlive `app`).
  std::function<Flag*(Command& app, Options& options)> add;
  /// The field's value as the flag writes it; empty when unset (an empty optional).
  std::function<std::string(const Options& options)> text;
  /// Further fields the flag writes, named in Validate()'s messages like `field` (with
  /// the flag in front: "--rest-window: rest_to_led_s: expected ...").
  std::vector<std::string> more_fields = {};
};

/// The field's name and an accessor for it, for the Flag factories below:
/// LIFTOFF_FIELD(engine.time_step_s).
#define LIFTOFF_FIELD(path) #path, [](auto& options) -> auto& { return options.path; }

namespace flags_internal {
template <typename T>
struct Unwrap {
  using type = T;
};
template <typename T>
struct Unwrap<std::optional<T>> {
  using type = T;
};
template <typename Options, typename Access>
using FieldType = std::remove_cvref_t<decltype(std::declval<Access>()(std::declval<Options&>()))>;
}  // namespace flags_internal

/// A number flag (double or int field, optional or not) in `unit` (a double field).
template <typename Options, typename Access>
FieldFlag<Options> NumberFlag(std::string flag, std::string field, Access access, FlagUnit unit,
                              std::string help) {
  using Field = flags_internal::FieldType<Options, Access>;
  using Value = typename flags_internal::Unwrap<Field>::type;
  FieldFlag<Options> bound{flag, std::move(field), unit.flag_per_field != 1.0, false, {}, {}};
  bound.text = [access, unit](const Options& options) -> std::string {
    const Field& value = access(options);
    if constexpr (!std::is_same_v<Field, Value>) {
      if (!value) return "";
      if constexpr (std::is_integral_v<Value>) return std::to_string(*value);
      else return FormatNumber(*value * unit.flag_per_field);
    } else if constexpr (std::is_integral_v<Value>) {
      return std::to_string(value);
    } else {
      return FormatNumber(value * unit.flag_per_field);
    }
  };
  bound.add = [flag, help, access, unit, text = bound.text](Command& app, Options& options) {
    Field& target = access(options);
    Flag* option = app.AddOptionFunction<Value>(
        flag,
        [&target, unit](const Value& value) {
          if constexpr (std::is_integral_v<Value>) {
            target = value;
          } else {
            target = value / unit.flag_per_field;
          }
        },
        help);
    return option->ShowDefaultFrom([&options, text] { return text(options); });
  };
  return bound;
}

/// A flag taking one of `words`, each standing for a value; `get` reads the field (nullopt:
/// unset), `set` writes it. Any other word: FlagError "--flag: expected a or b, got "c"".
template <typename Options, typename Value>
FieldFlag<Options> ChoiceFlagOf(std::string flag, std::string field,
                                std::vector<std::pair<std::string, Value>> words,
                                std::function<std::optional<Value>(const Options&)> get,
                                std::function<void(Options&, const Value&)> set,
                                std::string help) {
  std::vector<std::string> names;
  for (const auto& word : words) names.push_back(word.first);
  FieldFlag<Options> bound{flag, std::move(field), false, false, {}, {}};
  bound.text = [words, get](const Options& options) -> std::string {
    const std::optional<Value> value = get(options);
    if (!value) return "";
    for (const auto& [name, meaning] : words) {
      if (meaning == *value) return name;
    }
    return "";
  };
  bound.add = [flag, help, words, names, set, text = bound.text](Command& app,
                                                                 Options& options) {
    Flag* option = app.AddOptionFunction<std::string>(
        flag,
        [flag, words, names, set, &options](const std::string& given) {
          for (const auto& [name, meaning] : words) {
            if (name == given) return set(options, meaning);
          }
          throw FlagError(InvalidArgumentError(flag + ": expected " + OneOf(names) + ", got \"" +
                                               given + "\""));
        },
        help);
    return option->TypeName(Join(names, "|"))
        ->ShowDefaultFrom([&options, text] { return text(options); });
  };
  return bound;
}

/// A flag whose text `set` parses into the struct (a kInvalidArgument status naming the
/// flag when it cannot: thrown as FlagError); `get` writes the field back as the flag would
/// give it ("" when unset). `type_name` names the value in help ("x,y,w,h").
template <typename Options>
FieldFlag<Options> TextFlagOf(std::string flag, std::string field,
                              std::function<std::string(const Options&)> get,
                              std::function<Status(Options&, const std::string&)> set,
                              std::string type_name, std::string help) {
  FieldFlag<Options> bound{flag, std::move(field), false, false, {}, get};
  bound.add = [flag, help, type_name, set, get](Command& app, Options& options) {
    Flag* option = app.AddOptionFunction<std::string>(
        flag,
        [set, &options](const std::string& given) {
          if (Status parsed = set(options, given); !parsed.ok()) throw FlagError(parsed);
        },
        help);
    return option->TypeName(type_name)->ShowDefaultFrom([&options, get] { return get(options); });
  };
  return bound;
}

/// ChoiceFlagOf for a plain or optional field.
template <typename Options, typename Access, typename Value>
FieldFlag<Options> ChoiceFlag(std::string flag, std::string field, Access access,
                              std::vector<std::pair<std::string, Value>> words,
                              std::string help) {
  return ChoiceFlagOf<Options, Value>(
      std::move(flag), std::move(field), std::move(words),
      [access](const Options& options) -> std::optional<Value> { return access(options); },
      [access](Options& options, const Value& value) { access(options) = value; },
      std::move(help));
}

/// A flag without a value for a bool field: given means true.
template <typename Options, typename Access>
FieldFlag<Options> SwitchFlag(std::string flag, std::string field, Access access,
                              std::string help) {
  FieldFlag<Options> bound{flag, std::move(field), false, true, {}, {}};
  bound.text = [access](const Options& options) -> std::string {
    return access(options) ? "true" : "";
  };
  bound.add = [flag, help, access](Command& app, Options& options) {
    return app.AddSwitch(flag, access(options), help);
  };
  return bound;
}

/// A flag taking `count` comma-separated numbers ("1,2,3"); `get` reads them from the
/// struct, `set` writes them. Another count: FlagError naming the flag and `expected`.
template <typename Options>
FieldFlag<Options> NumbersFlag(std::string flag, std::string field, size_t count,
                               std::function<std::vector<double>(const Options&)> get,
                               std::function<void(Options&, const std::vector<double>&)> set,
                               std::string expected, std::string help) {
  FieldFlag<Options> bound{flag, std::move(field), false, false, {}, {}};
  bound.text = [get](const Options& options) { return JoinNumbers(get(options), ","); };
  bound.add = [flag, count, set, expected, help, text = bound.text](Command& app,
                                                                    Options& options) {
    Flag* option = app.AddOptionFunction<std::vector<double>>(
        flag,
        [flag, count, set, expected, &options](const std::vector<double>& values) {
          if (values.size() != count) {
            throw FlagError(InvalidArgumentError(flag + ": expected " + expected + ", got " +
                                                 std::to_string(values.size()) + " numbers"));
          }
          set(options, values);
        },
        help);
    return option->CommaSeparated()->ShowDefaultFrom([&options, text] { return text(options); });
  };
  return bound;
}

/// Adds every flag of `flags` to `app`, bound to `options` (which must outlive `app`).
template <typename Options>
void AddFlags(Command& app, const std::vector<FieldFlag<Options>>& flags, Options& options) {
  for (const FieldFlag<Options>& flag : flags) flag.add(app, options);
}

/// The flags whose field in `options` differs from a default-constructed Options, as a
/// command line would give them ("--friction 0.25 --rotation=-"); empty when none.
template <typename Options>
std::string DescribeChanged(const std::vector<FieldFlag<Options>>& flags,
                            const Options& options) {
  const Options defaults;
  std::string joined;
  for (const FieldFlag<Options>& flag : flags) {
    const std::string value = flag.text(options);
    if (value == flag.text(defaults)) continue;
    std::string given = flag.flag;
    if (!flag.is_switch) given += (!value.empty() && value.front() == '-' ? "=" : " ") + value;
    joined += (joined.empty() ? "" : " ") + given;
  }
  return joined;
}

/// `message` of a Validate() failure about field `field` rewritten to name `flag`: the
/// field's name replaced by the flag's ("--dt: expected ..."), or, when the flag's unit is
/// not the field's, put in front ("--ramp-deg: ramp_angle_rad: expected ..."); nullopt
/// when the message is not about `field` (it starts with "field:" or "field.", a nested
/// field's context written "outer: inner:" also matching "outer.inner").
std::optional<std::string> MessageNamingFlag(const std::string& message, const std::string& flag,
                                             const std::string& field, bool scaled);

/// `status` from Options' Validate() with the flag of the field it names in front; other
/// statuses as they are.
template <typename Options>
Status NameFlagIn(const Status& status, const std::vector<FieldFlag<Options>>& flags) {
  if (status.ok()) return status;
  for (const FieldFlag<Options>& flag : flags) {
    if (auto message = MessageNamingFlag(status.message(), flag.flag, flag.field, flag.scaled)) {
      return Status(status.code(), *message);
    }
    for (const std::string& field : flag.more_fields) {
      if (auto message = MessageNamingFlag(status.message(), flag.flag, field, true)) {
        return Status(status.code(), *message);
      }
    }
  }
  return status;
}

/// A comma-separated list flag ("--feet A,C") bound to `field`; its help shows the
/// field's value.
Flag* AddListOption(Command& app, const std::string& flag, std::vector<std::string>& field,
                    const std::string& help);

/// A subcommand on the command line: its Command (flags bound to its command struct) and
/// the function that runs that struct once parsed.
struct Subcommand {
  Command* app = nullptr;
  std::function<int(std::ostream& out, std::ostream& err)> run;
};

/// The Subcommand that runs `run` with `command` (the struct `app`'s flags are bound to).
template <typename Parsed>
Subcommand RunsWith(Command* app, std::shared_ptr<Parsed> command,
                    int (*run)(const Parsed&, std::ostream&, std::ostream&)) {
  return {app, [command = std::move(command), run](std::ostream& out, std::ostream& err) {
            return run(*command, out, err);
          }};
}

/// Adds the commands under `root` and returns their Subcommands (AddCommands).
using CommandTable = std::function<std::vector<Subcommand>(Command& root)>;

/// Parses `argv` with a root command (`description` in its help, `version` printed by
/// --version) that `table` fills, and runs the subcommand chosen. Exit codes: the Run
/// function's; usage errors kExitUsage; a FlagError its status' class; an exception
/// kExitInternal (docs/cli.md).
int RunCommandLine(const std::string& description, const std::string& version,
                   const CommandTable& table, int argc, const char* const* argv,
                   std::ostream& out, std::ostream& err);

}  // namespace liftoff::cli
