// Serial ports: libserialport finds, opens and configures real devices, termios opens
// pseudo-terminals, and one poll(2)-based core does the I/O for both.
#include "liftoff/capture/serial_port.h"

#include <fcntl.h>
#include <libserialport.h>
#include <poll.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <system_error>
#include <utility>

namespace liftoff::capture {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

std::string ErrnoText(int error) { return std::generic_category().message(error); }

std::string ToLower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return text;
}

// ---------------------------------------------------------------------------------------
// Timeouts

// A point in time that poll(2) waits towards; negative timeouts never expire.
class Deadline {
 public:
  explicit Deadline(int timeout_ms)
      : forever_(timeout_ms < 0),
        end_(Clock::now() + std::chrono::milliseconds(std::max(timeout_ms, 0))) {}

  bool Expired() const { return !forever_ && Clock::now() >= end_; }

  // milliseconds left for poll(2), rounded up so a wait never ends early; -1: forever
  int RemainingMs() const {
    if (forever_) return -1;
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(end_ - Clock::now());
    return static_cast<int>(std::clamp<int64_t>(left.count(), 0, INT_MAX));
  }

 private:
  bool forever_;
  Clock::time_point end_;
};

// ---------------------------------------------------------------------------------------
// The I/O both paths share

Status DeviceGone(const std::string& name, const std::string& why) {
  return IoError(name + ": device gone (" + why + ")");
}

// A port whose I/O is poll(2) plus read(2)/write(2) on a non-blocking descriptor.
class FdSerialPort : public SerialPort {
 public:
  Result<size_t> Read(std::span<uint8_t> buffer, int timeout_ms) override;
  Status Write(std::span<const uint8_t> bytes, int timeout_ms) override;
  const std::string& name() const override { return name_; }

 protected:
  explicit FdSerialPort(std::string name) : name_(std::move(name)) {}

  int fd_ = -1;
  std::string name_;
};

Result<size_t> FdSerialPort::Read(std::span<uint8_t> buffer, int timeout_ms) {
  if (fd_ < 0) return IoError(name_ + ": port is closed");
  const Deadline deadline(timeout_ms);
  for (;;) {
    // wait for bytes, a hang-up or the deadline; a signal ends the wait early
    pollfd poll_fd{fd_, POLLIN, 0};
    const int ready = poll(&poll_fd, 1, deadline.RemainingMs());
    if (ready == 0 || (ready < 0 && errno == EINTR)) return size_t{0};
    if (ready < 0) return IoError(name_ + ": poll: " + ErrnoText(errno));
    if (poll_fd.revents & POLLNVAL) return IoError(name_ + ": port is closed");
    // read what is there: a hung-up tty reads end of file, an unplugged one EIO
    const ssize_t count = read(fd_, buffer.data(), buffer.size());
    if (count > 0 || buffer.empty()) return static_cast<size_t>(std::max<ssize_t>(count, 0));
    if (count == 0) return DeviceGone(name_, "end of file");
    const int error = errno;
    const bool hung_up = (poll_fd.revents & (POLLHUP | POLLERR)) != 0;
    if ((error == EAGAIN || error == EINTR) && !hung_up) {
      if (deadline.Expired()) return size_t{0};
      continue;
    }
    return DeviceGone(name_, error == EAGAIN ? "hang-up" : ErrnoText(error));
  }
}

Status FdSerialPort::Write(std::span<const uint8_t> bytes, int timeout_ms) {
  if (fd_ < 0) return IoError(name_ + ": port is closed");
  const Deadline deadline(timeout_ms);
  size_t written = 0;
  while (written < bytes.size()) {
    // hand over as much as the device takes
    const ssize_t count = write(fd_, bytes.data() + written, bytes.size() - written);
    if (count > 0) {
      written += static_cast<size_t>(count);
      continue;
    }
    const int error = count < 0 ? errno : EAGAIN;
    if (error == EIO || error == ENXIO || error == ENODEV || error == EPIPE) {
      return DeviceGone(name_, ErrnoText(error));
    }
    if (error != EAGAIN && error != EINTR) return IoError(name_ + ": write: " + ErrnoText(error));
    // full: wait until it drains, or give up at the deadline
    if (deadline.Expired()) {
      return TimeoutError(name_ + ": write timed out after " + std::to_string(timeout_ms) +
                          " ms with " + std::to_string(written) + " of " +
                          std::to_string(bytes.size()) + " bytes sent");
    }
    pollfd poll_fd{fd_, POLLOUT, 0};
    if (poll(&poll_fd, 1, deadline.RemainingMs()) < 0 && errno != EINTR) {
      return IoError(name_ + ": poll: " + ErrnoText(errno));
    }
  }
  return Status::Ok();
}

// Turns a failed open(2) into the error a user can act on.
Status OpenError(const std::string& name, int error) {
  switch (error) {
    case ENOENT:
    case ENXIO:
    case ENODEV:
      return NotFoundError("no such serial device: " + name + " (" + ErrnoText(error) + ")");
    case EACCES:
    case EPERM:
      return IoError("cannot open " + name + ": " + ErrnoText(error) +
                     " (serial devices usually belong to the 'dialout' group: sudo usermod "
                     "-aG dialout $USER, then log in again)");
    case EBUSY:
      return IoError("cannot open " + name + ": " + ErrnoText(error) +
                     " (another program has it open)");
    default: return IoError("cannot open " + name + ": " + ErrnoText(error));
  }
}

// Makes a descriptor non-blocking and close-on-exec, as the I/O core expects.
Status PrepareDescriptor(int fd, const std::string& name) {
  const int flags = fcntl(fd, F_GETFL);
  if (flags < 0 || fcntl(fd, F_SETFL, flags | O_NONBLOCK) < 0 ||
      fcntl(fd, F_SETFD, FD_CLOEXEC) < 0) {
    return IoError(name + ": fcntl: " + ErrnoText(errno));
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------
// The termios path (pseudo-terminals)

struct SpeedConstant {
  int baud_rate;
  speed_t speed;
};
constexpr std::array<SpeedConstant, 30> kSpeeds = {{
    {50, B50},           {75, B75},           {110, B110},         {134, B134},
    {150, B150},         {200, B200},         {300, B300},         {600, B600},
    {1200, B1200},       {1800, B1800},       {2400, B2400},       {4800, B4800},
    {9600, B9600},       {19200, B19200},     {38400, B38400},     {57600, B57600},
    {115200, B115200},   {230400, B230400},   {460800, B460800},   {500000, B500000},
    {576000, B576000},   {921600, B921600},   {1000000, B1000000}, {1152000, B1152000},
    {1500000, B1500000}, {2000000, B2000000}, {2500000, B2500000}, {3000000, B3000000},
    {3500000, B3500000}, {4000000, B4000000},
}};

Status ApplyTermios(int fd, const std::string& name, const PortSettings& settings,
                    bool pseudo_terminal) {
  termios tio{};
  if (tcgetattr(fd, &tio) != 0) {
    return IoError(name + ": not a terminal (tcgetattr: " + ErrnoText(errno) + ")");
  }
  // raw bytes: no echo, no line editing, no CR/LF translation, no flow-control characters
  cfmakeraw(&tio);
  tio.c_cc[VMIN] = 0;
  tio.c_cc[VTIME] = 0;
  // framing
  tio.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
  tio.c_cflag |= CLOCAL | CREAD;
  constexpr std::array<tcflag_t, 4> kSizes = {CS5, CS6, CS7, CS8};
  tio.c_cflag |= kSizes[static_cast<size_t>(settings.data_bits - 5)];
  if (settings.parity == 'E') tio.c_cflag |= PARENB;
  if (settings.parity == 'O') tio.c_cflag |= PARENB | PARODD;
  if (settings.stop_bits == 2) tio.c_cflag |= CSTOPB;
  if (settings.hardware_flow_control) tio.c_cflag |= CRTSCTS;
  // speed: a pseudo-terminal has none, so an unusual rate only matters on a real line
  const auto speed = std::find_if(kSpeeds.begin(), kSpeeds.end(), [&](const auto& entry) {
    return entry.baud_rate == settings.baud_rate;
  });
  if (speed != kSpeeds.end()) {
    cfsetispeed(&tio, speed->speed);
    cfsetospeed(&tio, speed->speed);
  } else if (!pseudo_terminal) {
    return UnsupportedError(name + ": baud_rate " + std::to_string(settings.baud_rate) +
                            " has no termios constant (standard rates: 9600, 115200, ...)");
  }
  if (tcsetattr(fd, TCSANOW, &tio) != 0) {
    return IoError(name + ": tcsetattr: " + ErrnoText(errno));
  }
  return Status::Ok();
}

class TermiosSerialPort final : public FdSerialPort {
 public:
  TermiosSerialPort(int fd, std::string name) : FdSerialPort(std::move(name)) { fd_ = fd; }
  ~TermiosSerialPort() override { Close(); }

  void Close() override {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
  }
};

// ---------------------------------------------------------------------------------------
// The libserialport path (real devices)

// A libserialport error as a Status naming the device and what was being done.
Status SpStatus(sp_return result, const std::string& name, const std::string& what) {
  switch (result) {
    case SP_ERR_ARG:
      return InvalidArgumentError(name + ": " + what + ": rejected by libserialport");
    case SP_ERR_SUPP:
      return UnsupportedError(name + ": " + what + ": not supported by this device");
    case SP_ERR_MEM: return IoError(name + ": " + what + ": out of memory");
    case SP_ERR_FAIL: return IoError(name + ": " + what + ": " + ErrnoText(sp_last_error_code()));
    default: return Status::Ok();
  }
}

class LibSerialPort final : public FdSerialPort {
 public:
  LibSerialPort(sp_port* port, std::string name) : FdSerialPort(std::move(name)), port_(port) {}
  ~LibSerialPort() override {
    Close();
    sp_free_port(port_);
  }

  // opens the device and sets it up; the port stays closed on failure
  Status Open(const PortSettings& settings) {
    const sp_return opened = sp_open(port_, SP_MODE_READ_WRITE);
    if (opened == SP_ERR_FAIL) return OpenError(name_, sp_last_error_code());
    LIFTOFF_RETURN_IF_ERROR(SpStatus(opened, name_, "open"));
    open_ = true;
    // line settings
    const sp_parity parity = settings.parity == 'E'   ? SP_PARITY_EVEN
                             : settings.parity == 'O' ? SP_PARITY_ODD
                                                      : SP_PARITY_NONE;
    const sp_flowcontrol flow =
        settings.hardware_flow_control ? SP_FLOWCONTROL_RTSCTS : SP_FLOWCONTROL_NONE;
    LIFTOFF_RETURN_IF_ERROR(SpStatus(sp_set_baudrate(port_, settings.baud_rate), name_,
                                     "baud_rate " + std::to_string(settings.baud_rate)));
    LIFTOFF_RETURN_IF_ERROR(SpStatus(sp_set_bits(port_, settings.data_bits), name_,
                                     "data_bits " + std::to_string(settings.data_bits)));
    LIFTOFF_RETURN_IF_ERROR(
        SpStatus(sp_set_parity(port_, parity), name_, std::string("parity ") + settings.parity));
    LIFTOFF_RETURN_IF_ERROR(SpStatus(sp_set_stopbits(port_, settings.stop_bits), name_,
                                     "stop_bits " + std::to_string(settings.stop_bits)));
    LIFTOFF_RETURN_IF_ERROR(SpStatus(sp_set_flowcontrol(port_, flow), name_, "flow control"));
    // the I/O core works on libserialport's own descriptor
    int fd = -1;
    LIFTOFF_RETURN_IF_ERROR(SpStatus(sp_get_port_handle(port_, &fd), name_, "handle"));
    LIFTOFF_RETURN_IF_ERROR(PrepareDescriptor(fd, name_));
    fd_ = fd;
    return Status::Ok();
  }

  void Close() override {
    if (open_) sp_close(port_);
    open_ = false;
    fd_ = -1;
  }

 private:
  sp_port* port_;
  bool open_ = false;
};

// ---------------------------------------------------------------------------------------
// Finding ports

// The first line of a small sysfs file, without its newline; empty when unreadable.
std::string ReadSysfsLine(const fs::path& path) {
  std::ifstream file(path);
  std::string line;
  std::getline(file, line);
  return line;
}

// Whether two device paths name the same device (equal, or the same device number).
bool SameDevice(const std::string& a, const std::string& b) {
  if (a == b) return true;
  struct stat info_a {};
  struct stat info_b {};
  return stat(a.c_str(), &info_a) == 0 && stat(b.c_str(), &info_b) == 0 &&
         S_ISCHR(info_a.st_mode) && S_ISCHR(info_b.st_mode) && info_a.st_rdev == info_b.st_rdev;
}

// The active console devices: /dev/console, and those `console_list` names ("tty0
// ttyS0"). Without a list (no sysfs), only /dev/console.
std::vector<std::string> ConsoleDevices(const fs::path& console_list) {
  std::vector<std::string> devices = {"/dev/console"};
  std::istringstream names(ReadSysfsLine(console_list));
  for (std::string name; names >> name;) devices.push_back("/dev/" + name);
  return devices;
}

bool IsConsole(const std::string& device, const std::vector<std::string>& consoles) {
  return std::any_of(consoles.begin(), consoles.end(),
                     [&](const std::string& console) { return SameDevice(device, console); });
}

std::string TakeString(char* text) { return text ? std::string(text) : std::string(); }

// What libserialport knows of a device from sysfs; the name alone when it knows nothing.
PortInfo DescribePort(const std::string& device) {
  PortInfo info;
  info.name = device;
  info.description = fs::path(device).filename().string();
  info.transport = "native";
  info.stable_id = device;
  sp_port* port = nullptr;
  if (sp_get_port_by_name(device.c_str(), &port) != SP_OK) return info;
  // libserialport's strings live as long as the port structure
  const std::string description = TakeString(sp_get_port_description(port));
  if (!description.empty()) info.description = description;
  const sp_transport transport = sp_get_port_transport(port);
  if (transport == SP_TRANSPORT_USB) info.transport = "usb";
  if (transport == SP_TRANSPORT_BLUETOOTH) info.transport = "bluetooth";
  int vendor_id = 0;
  int product_id = 0;
  if (transport == SP_TRANSPORT_USB &&
      sp_get_port_usb_vid_pid(port, &vendor_id, &product_id) == SP_OK) {
    info.usb_vendor_id = vendor_id;
    info.usb_product_id = product_id;
    info.manufacturer = TakeString(sp_get_port_usb_manufacturer(port));
    info.product = TakeString(sp_get_port_usb_product(port));
    info.serial_number = TakeString(sp_get_port_usb_serial(port));
    char id[32];
    std::snprintf(id, sizeof(id), "usb:%04x:%04x", vendor_id & 0xffff, product_id & 0xffff);
    info.stable_id = id;
    if (!info.serial_number.empty()) info.stable_id += ":" + info.serial_number;
  }
  sp_free_port(port);
  return info;
}

// "available ports: /dev/ttyACM0 (usb:2341:0043:...), /dev/ttyS0" for error messages.
std::string AvailablePortsText() {
  const Result<std::vector<PortInfo>> ports = ListPorts();
  if (!ports.ok() || ports->empty()) return "no serial ports found (liftoff ports lists them)";
  std::string text = "available ports:";
  for (size_t i = 0; i < ports->size(); ++i) {
    const PortInfo& port = (*ports)[i];
    text += (i ? ", " : " ") + port.name;
    if (port.stable_id != port.name) text += " (" + port.stable_id + ")";
  }
  return text;
}

// The device a stable id names: an exact match first, else a unique prefix ("usb:2341:0043").
Result<std::string> DeviceForStableId(const std::string& id) {
  LIFTOFF_ASSIGN_OR_RETURN(const std::vector<PortInfo> ports, ListPorts());
  const std::string wanted = ToLower(id);
  std::vector<const PortInfo*> exact, prefixed;
  for (const PortInfo& port : ports) {
    const std::string candidate = ToLower(port.stable_id);
    if (candidate == wanted) exact.push_back(&port);
    if (candidate.rfind(wanted + ":", 0) == 0) prefixed.push_back(&port);
  }
  const std::vector<const PortInfo*>& matches = exact.empty() ? prefixed : exact;
  if (matches.empty()) {
    return NotFoundError("no serial port has the id \"" + id + "\"; " + AvailablePortsText());
  }
  if (matches.size() > 1) {
    std::string names;
    for (const PortInfo* port : matches) names += (names.empty() ? "" : ", ") + port->stable_id;
    return InvalidArgumentError("the id \"" + id + "\" matches several ports (" + names +
                                "); give a full id or a device path");
  }
  return matches.front()->name;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// Public functions

Status PortSettings::Validate() const {
  if (baud_rate < 1 || baud_rate > 4000000) {
    return InvalidArgumentError("PortSettings.baud_rate: expected 1..4000000 bits/s, got " +
                                std::to_string(baud_rate));
  }
  if (data_bits < 5 || data_bits > 8) {
    return InvalidArgumentError("PortSettings.data_bits: expected 5, 6, 7 or 8, got " +
                                std::to_string(data_bits));
  }
  if (parity != 'N' && parity != 'E' && parity != 'O') {
    return InvalidArgumentError(
        "PortSettings.parity: expected 'N' (none), 'E' (even) or 'O' (odd), got " +
        (parity >= 0x20 && parity < 0x7f ? "'" + std::string(1, parity) + "'"
                                         : "character code " + std::to_string(parity)));
  }
  if (stop_bits != 1 && stop_bits != 2) {
    return InvalidArgumentError("PortSettings.stop_bits: expected 1 or 2, got " +
                                std::to_string(stop_bits));
  }
  return Status::Ok();
}

SerialPort::~SerialPort() = default;

Result<std::vector<PortInfo>> ListPorts() {
  constexpr char kTtyClass[] = "/sys/class/tty";
  std::error_code error;
  fs::directory_iterator entries(kTtyClass, error);
  const std::vector<std::string> consoles = ConsoleDevices(kConsoleListPath);
  std::vector<PortInfo> ports;
  for (; !error && entries != fs::directory_iterator(); entries.increment(error)) {
    const fs::directory_entry& entry = *entries;
    // a class entry links to its device (older kernels: its `device` link does)
    std::error_code link_error;
    fs::path target = fs::read_symlink(entry.path(), link_error);
    if (link_error) target = fs::read_symlink(entry.path() / "device", link_error);
    if (link_error) continue;
    // virtual terminals and pseudo-terminals are no serial ports
    if (target.string().find("virtual") != std::string::npos) continue;
    // serial8250 reserves ports that may not exist; sysfs `type` 0 means none is there
    // (libserialport opens each one to ask, which could touch the console)
    if (target.string().find("serial8250") != std::string::npos) {
      const std::string type = ReadSysfsLine(entry.path() / "type");
      if (type.empty() || type == "0") continue;
    }
    PortInfo info = DescribePort("/dev/" + entry.path().filename().string());
    info.is_console = IsConsole(info.name, consoles);
    ports.push_back(std::move(info));
  }
  if (error) {
    return IoError(std::string("cannot list serial ports: ") + kTtyClass + ": " + error.message());
  }
  std::sort(ports.begin(), ports.end(),
            [](const PortInfo& a, const PortInfo& b) { return a.name < b.name; });
  return ports;
}

std::string FormatPortList(const std::vector<PortInfo>& ports) {
  if (ports.empty()) return "no serial ports found\n";
  // one row of cells per port, under a header
  std::vector<std::array<std::string, 5>> rows = {
      {"device", "description", "usb id", "serial number", "stable id"}};
  for (const PortInfo& port : ports) {
    std::string usb_id = "-";
    if (port.usb_vendor_id && port.usb_product_id) {
      char text[16];
      std::snprintf(text, sizeof(text), "%04x:%04x", *port.usb_vendor_id & 0xffff,
                    *port.usb_product_id & 0xffff);
      usb_id = text;
    }
    rows.push_back({port.name, port.description + (port.is_console ? " (console)" : ""), usb_id,
                    port.serial_number.empty() ? "-" : port.serial_number, port.stable_id});
  }
  // columns as wide as their widest cell, two spaces apart
  std::array<size_t, 5> widths{};
  for (const auto& row : rows) {
    for (size_t column = 0; column < row.size(); ++column) {
      widths[column] = std::max(widths[column], row[column].size());
    }
  }
  std::string table;
  for (const auto& row : rows) {
    std::string line;
    for (size_t column = 0; column < row.size(); ++column) {
      line += row[column];
      if (column + 1 < row.size())
        line += std::string(widths[column] - row[column].size() + 2, ' ');
    }
    table += line + "\n";
  }
  return table;
}

bool IsPseudoTerminal(const std::filesystem::path& path) {
  std::error_code error;
  const fs::path resolved = fs::canonical(path, error);
  struct stat info {};
  if (error || stat(resolved.c_str(), &info) != 0 || !S_ISCHR(info.st_mode)) return false;
  // Unix98 pty slaves (/dev/pts/N) have majors 136-143 (the kernel's devices.txt)
  const unsigned major_number = major(info.st_rdev);
  return major_number >= 136 && major_number <= 143;
}

Result<std::unique_ptr<SerialPort>> OpenTermiosPort(const std::filesystem::path& path,
                                                    const PortSettings& settings) {
  LIFTOFF_RETURN_IF_ERROR(settings.Validate());
  const int fd = ::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) return OpenError(path.string(), errno);
  std::error_code error;
  const fs::path resolved = fs::canonical(path, error);
  auto port = std::make_unique<TermiosSerialPort>(fd, error ? path.string() : resolved.string());
  LIFTOFF_RETURN_IF_ERROR(ApplyTermios(fd, port->name(), settings, IsPseudoTerminal(path)));
  return std::unique_ptr<SerialPort>(std::move(port));
}

bool IsStableId(std::string_view port) { return ToLower(std::string(port.substr(0, 4))) == "usb:"; }

Result<std::unique_ptr<SerialPort>> OpenSerialPort(const std::string& port,
                                                   const PortSettings& settings,
                                                   const std::filesystem::path& console_list_path) {
  LIFTOFF_RETURN_IF_ERROR(settings.Validate());
  // a stable id names a device path
  std::string device = port;
  if (IsStableId(port)) {
    LIFTOFF_ASSIGN_OR_RETURN(device, DeviceForStableId(port));
  }
  // the device itself, through any symlinks
  std::error_code error;
  const fs::path resolved = fs::canonical(device, error);
  if (error == std::errc::no_such_file_or_directory || error == std::errc::not_a_directory) {
    return NotFoundError("no such serial port: " + device + "; " + AvailablePortsText());
  }
  if (error) return IoError("cannot open " + device + ": " + error.message());
  struct stat info {};
  if (stat(resolved.c_str(), &info) != 0 || !S_ISCHR(info.st_mode)) {
    return InvalidArgumentError(device + " is not a serial port (not a character device)");
  }
  // never the console, unless asked
  if (!settings.allow_console && IsConsole(resolved.string(), ConsoleDevices(console_list_path))) {
    return InvalidArgumentError(device + " is this machine's active console (" +
                                console_list_path.string() +
                                "); refusing to open it (PortSettings.allow_console overrides)");
  }
  // pseudo-terminals through termios, real devices through libserialport
  if (IsPseudoTerminal(resolved)) return OpenTermiosPort(resolved, settings);
  sp_port* raw_port = nullptr;
  if (sp_get_port_by_name(resolved.c_str(), &raw_port) != SP_OK) {
    return InvalidArgumentError(device +
                                " is not a serial port libserialport knows (no entry in "
                                "/sys/class/tty); " +
                                AvailablePortsText());
  }
  auto serial_port = std::make_unique<LibSerialPort>(raw_port, resolved.string());
  LIFTOFF_RETURN_IF_ERROR(serial_port->Open(settings));
  return std::unique_ptr<SerialPort>(std::move(serial_port));
}

// ---------------------------------------------------------------------------------------
// PseudoTerminal

PseudoTerminal::PseudoTerminal(int master_fd, int slave_fd, std::string slave_path)
    : master_fd_(master_fd), slave_fd_(slave_fd), slave_path_(std::move(slave_path)) {}

PseudoTerminal::PseudoTerminal(PseudoTerminal&& other) noexcept
    : master_fd_(std::exchange(other.master_fd_, -1)),
      slave_fd_(std::exchange(other.slave_fd_, -1)),
      slave_path_(std::move(other.slave_path_)) {}

PseudoTerminal& PseudoTerminal::operator=(PseudoTerminal&& other) noexcept {
  if (this != &other) {
    CloseMaster();
    master_fd_ = std::exchange(other.master_fd_, -1);
    slave_fd_ = std::exchange(other.slave_fd_, -1);
    slave_path_ = std::move(other.slave_path_);
  }
  return *this;
}

PseudoTerminal::~PseudoTerminal() { CloseMaster(); }

Result<PseudoTerminal> PseudoTerminal::Open() {
  // a master, its slave unlocked
  const int master = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (master < 0) return IoError("cannot open a pseudo-terminal: " + ErrnoText(errno));
  char slave_name[128];
  if (grantpt(master) != 0 || unlockpt(master) != 0 ||
      ptsname_r(master, slave_name, sizeof(slave_name)) != 0) {
    const int error = errno;
    ::close(master);
    return IoError("cannot set up a pseudo-terminal: " + ErrnoText(error));
  }
  PseudoTerminal terminal(master, -1, slave_name);
  // the slave held open and raw, so bytes pass untouched both ways
  terminal.slave_fd_ = ::open(slave_name, O_RDWR | O_NOCTTY | O_CLOEXEC);
  if (terminal.slave_fd_ < 0) {
    return IoError(std::string("cannot open ") + slave_name + ": " + ErrnoText(errno));
  }
  termios tio{};
  if (tcgetattr(terminal.slave_fd_, &tio) != 0) {
    return IoError(std::string(slave_name) + ": tcgetattr: " + ErrnoText(errno));
  }
  cfmakeraw(&tio);
  if (tcsetattr(terminal.slave_fd_, TCSANOW, &tio) != 0) {
    return IoError(std::string(slave_name) + ": tcsetattr: " + ErrnoText(errno));
  }
  return terminal;
}

void PseudoTerminal::CloseSlave() {
  if (slave_fd_ >= 0) ::close(slave_fd_);
  slave_fd_ = -1;
}

void PseudoTerminal::CloseMaster() {
  CloseSlave();
  if (master_fd_ >= 0) ::close(master_fd_);
  master_fd_ = -1;
}

}  // namespace liftoff::capture
