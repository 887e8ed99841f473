// Serial ports behind one interface: real devices through libserialport (listing with USB
// identifiers, opening by path or by a stable id, baud rate and framing), and a POSIX
// termios path for pseudo-terminals, which libserialport 0.1.1 cannot open (it needs a
// /sys/class/tty entry and modem-control ioctls a pty lacks).
//
// Both paths do their I/O the same way, with poll(2) on the device's file descriptor:
// libserialport 0.1.1's reads cannot tell a hung-up device from a quiet one (a hung-up tty
// reads 0 bytes, which its blocking read retries until the timeout), and "the device is
// gone" is the one thing a capture must not miss.
//
// Safety: OpenSerialPort refuses the machine's active console device (a serial console
// such as /dev/ttyS0 carries the kernel's and the login's traffic), and listing never opens
// a device: it reads sysfs only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "liftoff/core/status.h"

namespace liftoff::capture {

/// Where Linux lists the active console devices ("tty0 ttyS0", names under /dev).
inline constexpr char kConsoleListPath[] = "/sys/class/tty/console/active";

/// Line settings of a serial port.
struct PortSettings {
  /// Line speed, bits/s (1 .. 4,000,000). Ignored by pseudo-terminals when it is not a
  /// standard termios speed.
  int baud_rate = 115200;
  /// Data bits per character (5 .. 8).
  int data_bits = 8;
  /// Parity: 'N' none, 'E' even, 'O' odd.
  char parity = 'N';
  /// Stop bits (1 or 2).
  int stop_bits = 1;
  /// RTS/CTS hardware flow control.
  bool hardware_flow_control = false;
  /// Allow opening the machine's active console device. Off: OpenSerialPort refuses it
  /// with kInvalidArgument.
  bool allow_console = false;

  /// kInvalidArgument naming the field and its allowed values.
  Status Validate() const;
};

/// One serial port found on the machine.
struct PortInfo {
  /// Device path, e.g. "/dev/ttyACM0".
  std::string name;
  /// Human-readable description (the USB product name, else the device's name).
  std::string description;
  /// "usb", "native" or "bluetooth".
  std::string transport;
  /// USB vendor and product ids, when the port is a USB device.
  std::optional<int> usb_vendor_id;
  std::optional<int> usb_product_id;
  /// USB strings; empty when unknown.
  std::string manufacturer;
  std::string product;
  std::string serial_number;
  /// A name that survives replugging and renumbering: "usb:2341:0043:<serial>" (vendor
  /// and product ids as 4 lower-case hex digits; ":<serial>" only when the device reports
  /// one), else the device path. OpenSerialPort accepts it.
  std::string stable_id;
  /// The device is one of the machine's active consoles (OpenSerialPort refuses it).
  bool is_console = false;
};

/// The serial ports of this machine, sorted by name. Reads sysfs only, never opens a
/// device (libserialport 0.1.1's own sp_list_ports opens every serial8250 port to probe
/// it; here a port's sysfs `type` attribute answers that question instead). Virtual
/// terminals and pseudo-terminals are not listed. kIo when /sys/class/tty cannot be read.
Result<std::vector<PortInfo>> ListPorts();

/// A readable table of `ports` for the terminal: device, description, USB vid:pid, serial
/// number and stable id, one port a line, under a header line. "no serial ports found"
/// when empty.
std::string FormatPortList(const std::vector<PortInfo>& ports);

/// An open serial port. Read and Write may run on different threads at once; Close must
/// not race with either.
class SerialPort {
 public:
  virtual ~SerialPort();

  /// Waits up to `timeout_ms` (0: do not wait; negative: wait indefinitely) for bytes and
  /// returns as soon as any arrive, with at most buffer.size() of them. 0 bytes: the
  /// timeout passed, or a signal interrupted the wait (so a Ctrl-C flag is seen at once).
  /// kIo when the device is gone (unplugged, pseudo-terminal master
  /// closed: a hang-up, EIO or end of file); the port stays gone, so close it and open
  /// the device again when it returns.
  virtual Result<size_t> Read(std::span<uint8_t> buffer, int timeout_ms) = 0;

  /// Writes all of `bytes`, waiting up to `timeout_ms` in all (negative: indefinitely)
  /// for the device to take them. kTimeout (saying how many bytes went out) when it did
  /// not; kIo when the device is gone.
  virtual Status Write(std::span<const uint8_t> bytes, int timeout_ms) = 0;

  /// Closes the device; Read and Write then fail with kIo. Idempotent.
  virtual void Close() = 0;

  /// The device path that was opened (symlinks resolved), e.g. "/dev/ttyACM0".
  virtual const std::string& name() const = 0;
};

/// Whether `port` is a stable id ("usb:2341:0043:<serial>", any case) rather than a
/// path: OpenSerialPort looks it up in ListPorts, and it may name a device that is
/// absent for now (unplugged) and comes back.
bool IsStableId(std::string_view port);

/// Opens `port`: a device path ("/dev/ttyACM0", or a symlink such as
/// /dev/serial/by-id/...), or a stable id from ListPorts ("usb:2341:0043:<serial>"; a
/// unique prefix such as "usb:2341:0043" is enough). A path that resolves to a
/// pseudo-terminal goes through OpenTermiosPort, anything else through libserialport.
/// Errors: the settings' kInvalidArgument; kNotFound for a missing device or an unknown
/// id (the message lists the available ports); kInvalidArgument for an ambiguous id, for
/// a path that is not a serial port, and for an active console device (listed in
/// `console_list_path`, a parameter only so tests can point it elsewhere) unless
/// settings.allow_console; kIo with the OS error when opening or configuring fails
/// (permission denied: the message suggests the dialout group).
Result<std::unique_ptr<SerialPort>> OpenSerialPort(
    const std::string& port, const PortSettings& settings,
    const std::filesystem::path& console_list_path = kConsoleListPath);

/// Opens a terminal device through POSIX termios: O_NOCTTY, raw mode (no echo, no line
/// editing, no CR/LF translation), the settings applied as far as the device allows (a
/// Linux pseudo-terminal keeps the speed, stop bits and flow control but ignores them,
/// and forces 8 data bits without parity). Made for
/// pseudo-terminals; does not check for the console (OpenSerialPort does). kNotFound for
/// a missing path, kIo (with the OS error) when it cannot be opened or is not a terminal,
/// kUnsupported for a baud rate termios has no constant for on a real device.
Result<std::unique_ptr<SerialPort>> OpenTermiosPort(const std::filesystem::path& path,
                                                    const PortSettings& settings);

/// Whether `path` resolves (through symlinks) to a pseudo-terminal's slave side
/// (/dev/pts/N, or a Unix98 pty device number). False for missing paths.
bool IsPseudoTerminal(const std::filesystem::path& path);

/// A pseudo-terminal pair for tests and the controller emulator: the emulator plays the
/// device on the master side, the capture opens slave_path() like a serial port.
///
/// The slave is put in raw mode (no echo, no CR/LF translation), and PseudoTerminal keeps
/// a slave file descriptor of its own open until CloseSlave(), CloseMaster() or
/// destruction. Why: on Linux, once the last slave descriptor closes, reading the master
/// fails with EIO (and poll reports a hang-up), so a master that starts before any reader,
/// or outlives one, would see errors. With the slave held open the master side behaves
/// like a device on a cable nobody listens to:
/// its reads wait, and its writes are buffered by the kernel until a reader opens the
/// slave (a write blocks, or fails with EAGAIN on a non-blocking master, when the buffer
/// of some kilobytes is full). A reader that comes later reads what is buffered.
class PseudoTerminal {
 public:
  /// A new pair. kIo with the OS error when the system has none to give.
  static Result<PseudoTerminal> Open();

  PseudoTerminal(PseudoTerminal&& other) noexcept;
  PseudoTerminal& operator=(PseudoTerminal&& other) noexcept;
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;
  ~PseudoTerminal();

  /// The master side's file descriptor (blocking, close-on-exec); -1 after CloseMaster().
  int master_fd() const { return master_fd_; }
  /// The slave's device path, e.g. "/dev/pts/3".
  const std::string& slave_path() const { return slave_path_; }

  /// Closes the held slave descriptor: from then on, the master reads EIO whenever no
  /// reader has the slave open.
  void CloseSlave();
  /// Closes the master (and the held slave descriptor): the device is gone, and a reader
  /// of the slave gets kIo. The kernel's hang-up discards bytes the reader has not read
  /// yet, as unplugging a device does.
  void CloseMaster();

 private:
  PseudoTerminal(int master_fd, int slave_fd, std::string slave_path);

  int master_fd_ = -1;
  int slave_fd_ = -1;
  std::string slave_path_;
};

}  // namespace liftoff::capture
