// The serial port layer over pseudo-terminals (never a real device: /dev/ttyS0 is this
// machine's console), its settings, its errors and the port list.
#include "liftoff/capture/serial_port.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_support.h"

namespace liftoff::capture {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using Clock = std::chrono::steady_clock;

int64_t MillisecondsSince(Clock::time_point start) {
  return std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - start).count();
}

// Bytes that a cooked terminal would mangle (CR, LF, ^C, ^D, XON/XOFF, DEL, 0xff) among
// pseudo-random ones: an xorshift generator, so the expected stream is known.
std::vector<uint8_t> TestBytes(size_t count) {
  std::vector<uint8_t> bytes(count);
  uint32_t state = 2463534242u;
  for (size_t i = 0; i < count; ++i) {
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    bytes[i] = static_cast<uint8_t>(state >> 24);
  }
  const uint8_t special[] = {'\r', '\n', 0x03, 0x04, 0x11, 0x13, 0x7f, 0xff, 0x00, 0x1a};
  for (size_t i = 0; i < sizeof(special) && i < count; ++i) bytes[i] = special[i];
  return bytes;
}

// Writes bytes into a descriptor from a thread, without blocking, until done or stopped;
// the destructor stops and joins it, so a failing test never leaves it behind.
class BackgroundWriter {
 public:
  BackgroundWriter(int fd, std::vector<uint8_t> bytes) : fd_(fd), bytes_(std::move(bytes)) {
    fcntl(fd_, F_SETFL, fcntl(fd_, F_GETFL) | O_NONBLOCK);
    thread_ = std::thread([this] { Run(); });
  }
  ~BackgroundWriter() {
    stop_ = true;
    thread_.join();
  }

 private:
  void Run() {
    size_t written = 0;
    while (written < bytes_.size() && !stop_) {
      const ssize_t count = write(fd_, bytes_.data() + written, bytes_.size() - written);
      if (count > 0) {
        written += static_cast<size_t>(count);
      } else {
        pollfd poll_fd{fd_, POLLOUT, 0};
        poll(&poll_fd, 1, 20);
      }
    }
  }

  int fd_;
  std::vector<uint8_t> bytes_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// Everything the master side receives within `timeout_ms`, up to `count` bytes.
std::string ReadFromMaster(int master_fd, size_t count, int timeout_ms) {
  std::string received;
  const Clock::time_point start = Clock::now();
  while (received.size() < count && MillisecondsSince(start) < timeout_ms) {
    pollfd poll_fd{master_fd, POLLIN, 0};
    if (poll(&poll_fd, 1, 20) <= 0) continue;
    char buffer[4096];
    const ssize_t n = read(master_fd, buffer, sizeof(buffer));
    if (n <= 0) break;
    received.append(buffer, static_cast<size_t>(n));
  }
  return received;
}

// A console list naming the pseudo-terminal as the console, in a scratch folder.
fs::path ConsoleListNaming(const testing::ScratchDir& scratch, const std::string& device) {
  const fs::path list = scratch / "console_active";
  testing::WriteFile(list, "tty0 " + device.substr(std::string("/dev/").size()) + "\n");
  return list;
}

PseudoTerminal OpenTerminal() {
  Result<PseudoTerminal> terminal = PseudoTerminal::Open();
  EXPECT_TRUE(terminal.ok()) << terminal.status().ToString();
  return std::move(terminal).value();
}

// ---------------------------------------------------------------------------------------
// Settings

TEST(PortSettings, DefaultsAre115200Baud8N1WithoutFlowControl) {
  const PortSettings settings;
  EXPECT_TRUE(settings.Validate().ok());
  EXPECT_EQ(settings.baud_rate, 115200);
  EXPECT_EQ(settings.data_bits, 8);
  EXPECT_EQ(settings.parity, 'N');
  EXPECT_EQ(settings.stop_bits, 1);
  EXPECT_FALSE(settings.hardware_flow_control);
  EXPECT_FALSE(settings.allow_console);
}

TEST(PortSettings, ValidateNamesTheFieldAndItsAllowedValues) {
  PortSettings baud;
  baud.baud_rate = 0;
  EXPECT_EQ(baud.Validate().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(baud.Validate().message(), HasSubstr("baud_rate: expected 1..4000000"));
  EXPECT_THAT(baud.Validate().message(), HasSubstr("got 0"));

  PortSettings bits;
  bits.data_bits = 9;
  EXPECT_THAT(bits.Validate().message(), HasSubstr("data_bits: expected 5, 6, 7 or 8, got 9"));

  PortSettings parity;
  parity.parity = 'X';
  EXPECT_THAT(parity.Validate().message(),
              HasSubstr("parity: expected 'N' (none), 'E' (even) or 'O' (odd), got 'X'"));

  PortSettings stop;
  stop.stop_bits = 3;
  EXPECT_THAT(stop.Validate().message(), HasSubstr("stop_bits: expected 1 or 2, got 3"));
}

TEST(SerialPort, OpenRejectsInvalidSettingsBeforeTouchingTheDevice) {
  PortSettings settings;
  settings.data_bits = 4;
  const auto port = OpenSerialPort("/dev/liftoff-no-such-port", settings);
  ASSERT_FALSE(port.ok());
  EXPECT_EQ(port.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(port.status().message(), HasSubstr("data_bits"));
}

// ---------------------------------------------------------------------------------------
// Pseudo-terminals

TEST(SerialPort, RecognisesStableIdsInAnyCase) {
  EXPECT_TRUE(IsStableId("usb:2341:0043:ABC"));
  EXPECT_TRUE(IsStableId("USB:2341:0043"));
  EXPECT_TRUE(IsStableId("Usb:"));
  EXPECT_FALSE(IsStableId("/dev/ttyACM0"));
  EXPECT_FALSE(IsStableId("usb"));
  EXPECT_FALSE(IsStableId(""));
}

TEST(SerialPort, RecognisesPseudoTerminals) {
  PseudoTerminal terminal = OpenTerminal();
  testing::ScratchDir scratch;
  fs::create_symlink(terminal.slave_path(), scratch / "robot");
  testing::WriteFile(scratch / "file", "not a device");

  EXPECT_TRUE(IsPseudoTerminal(terminal.slave_path()));
  EXPECT_TRUE(IsPseudoTerminal(scratch / "robot"));
  EXPECT_FALSE(IsPseudoTerminal("/dev/ptmx"));  // the master multiplexer, not a slave
  EXPECT_FALSE(IsPseudoTerminal("/dev/null"));
  EXPECT_FALSE(IsPseudoTerminal(scratch / "file"));
  EXPECT_FALSE(IsPseudoTerminal(scratch / "missing"));
}

TEST(SerialPort, DeliversAMegabyteFromTheMasterByteForByte) {
  PseudoTerminal terminal = OpenTerminal();
  auto port = OpenSerialPort(terminal.slave_path(), PortSettings{});
  ASSERT_TRUE(port.ok()) << port.status().ToString();
  EXPECT_EQ((*port)->name(), terminal.slave_path());

  const std::vector<uint8_t> sent = TestBytes(1 << 20);
  BackgroundWriter writer(terminal.master_fd(), sent);
  std::vector<uint8_t> received;
  received.reserve(sent.size());
  std::vector<uint8_t> buffer(8192);
  while (received.size() < sent.size()) {
    const Result<size_t> count = (*port)->Read(buffer, 2000);
    ASSERT_TRUE(count.ok()) << count.status().ToString();
    ASSERT_GT(*count, 0u) << "stalled after " << received.size() << " bytes";
    received.insert(received.end(), buffer.data(), buffer.data() + *count);
  }
  EXPECT_EQ(received.size(), sent.size());
  EXPECT_TRUE(received == sent) << "the bytes differ";
}

TEST(SerialPort, OpensAPseudoTerminalThroughASymlink) {
  PseudoTerminal terminal = OpenTerminal();
  testing::ScratchDir scratch;
  fs::create_symlink(terminal.slave_path(), scratch / "laika");
  auto port = OpenSerialPort((scratch / "laika").string(), PortSettings{});
  ASSERT_TRUE(port.ok()) << port.status().ToString();
  EXPECT_EQ((*port)->name(), terminal.slave_path());

  ASSERT_EQ(write(terminal.master_fd(), "$S,1\r\n", 6), 6);
  uint8_t buffer[16];
  const Result<size_t> count = (*port)->Read(buffer, 2000);
  ASSERT_TRUE(count.ok()) << count.status().ToString();
  EXPECT_EQ(std::string(reinterpret_cast<char*>(buffer), *count), "$S,1\r\n");
}

TEST(SerialPort, WriteReachesTheMasterUntranslated) {
  PseudoTerminal terminal = OpenTerminal();
  auto port = OpenSerialPort(terminal.slave_path(), PortSettings{});
  ASSERT_TRUE(port.ok()) << port.status().ToString();
  const std::string command = "$C,START,30\r\n\x03\x04\x11";
  const Status written =
      (*port)->Write({reinterpret_cast<const uint8_t*>(command.data()), command.size()}, 1000);
  ASSERT_TRUE(written.ok()) << written.ToString();
  EXPECT_EQ(ReadFromMaster(terminal.master_fd(), command.size(), 2000), command);
}

TEST(SerialPort, ReadReturnsNothingWhenTheTimeoutPasses) {
  PseudoTerminal terminal = OpenTerminal();
  auto port = OpenSerialPort(terminal.slave_path(), PortSettings{});
  ASSERT_TRUE(port.ok()) << port.status().ToString();
  uint8_t buffer[64];

  const Clock::time_point start = Clock::now();
  const Result<size_t> count = (*port)->Read(buffer, 50);
  const int64_t elapsed_ms = MillisecondsSince(start);
  ASSERT_TRUE(count.ok()) << count.status().ToString();
  EXPECT_EQ(*count, 0u);
  EXPECT_GE(elapsed_ms, 50);
  EXPECT_LT(elapsed_ms, 1000);

  const Clock::time_point poll_start = Clock::now();
  const Result<size_t> polled = (*port)->Read(buffer, 0);
  ASSERT_TRUE(polled.ok());
  EXPECT_EQ(*polled, 0u);
  EXPECT_LT(MillisecondsSince(poll_start), 50);
}

TEST(SerialPort, ReadFailsWithIoWhenTheMasterCloses) {
  PseudoTerminal terminal = OpenTerminal();
  auto port = OpenSerialPort(terminal.slave_path(), PortSettings{});
  ASSERT_TRUE(port.ok()) << port.status().ToString();

  // a reader waiting in Read wakes up when the device goes away
  std::thread unplug([&terminal] {
    std::this_thread::sleep_for(std::chrono::milliseconds(30));
    terminal.CloseMaster();
  });
  uint8_t buffer[64];
  const Clock::time_point start = Clock::now();
  const Result<size_t> count = (*port)->Read(buffer, 5000);
  const int64_t elapsed_ms = MillisecondsSince(start);
  unplug.join();
  ASSERT_FALSE(count.ok());
  EXPECT_EQ(count.status().code(), StatusCode::kIo);
  EXPECT_THAT(count.status().message(), HasSubstr(terminal.slave_path()));
  EXPECT_THAT(count.status().message(), HasSubstr("device gone"));
  EXPECT_LT(elapsed_ms, 2000);

  // and it stays gone, for writes too
  EXPECT_EQ((*port)->Read(buffer, 10).status().code(), StatusCode::kIo);
  const uint8_t byte = 'x';
  EXPECT_EQ((*port)->Write({&byte, 1}, 100).code(), StatusCode::kIo);
}

TEST(SerialPort, WriteTimesOutWhenNobodyReadsTheMaster) {
  PseudoTerminal terminal = OpenTerminal();
  auto port = OpenSerialPort(terminal.slave_path(), PortSettings{});
  ASSERT_TRUE(port.ok()) << port.status().ToString();
  const std::vector<uint8_t> bytes = TestBytes(1 << 20);
  const Clock::time_point start = Clock::now();
  const Status written = (*port)->Write(bytes, 100);
  EXPECT_EQ(written.code(), StatusCode::kTimeout);
  EXPECT_THAT(written.message(), HasSubstr("of 1048576 bytes sent"));
  EXPECT_GE(MillisecondsSince(start), 100);
}

TEST(SerialPort, ClosedPortFailsWithIo) {
  PseudoTerminal terminal = OpenTerminal();
  auto port = OpenSerialPort(terminal.slave_path(), PortSettings{});
  ASSERT_TRUE(port.ok()) << port.status().ToString();
  (*port)->Close();
  (*port)->Close();
  uint8_t buffer[4];
  EXPECT_EQ((*port)->Read(buffer, 10).status().code(), StatusCode::kIo);
  EXPECT_THAT((*port)->Read(buffer, 10).status().message(), HasSubstr("closed"));
}

TEST(SerialPort, TermiosPathAppliesWhatAPseudoTerminalKeepsAndRawMode) {
  PseudoTerminal terminal = OpenTerminal();
  PortSettings settings;
  settings.baud_rate = 9600;
  settings.data_bits = 7;
  settings.parity = 'E';
  settings.stop_bits = 2;
  settings.hardware_flow_control = true;
  auto port = OpenTermiosPort(terminal.slave_path(), settings);
  ASSERT_TRUE(port.ok()) << port.status().ToString();

  // the settings live in the tty: read them through a second descriptor
  const int fd = open(terminal.slave_path().c_str(), O_RDWR | O_NOCTTY);
  ASSERT_GE(fd, 0);
  termios tio{};
  ASSERT_EQ(tcgetattr(fd, &tio), 0);
  close(fd);
  EXPECT_TRUE(tio.c_cflag & CSTOPB);
  EXPECT_TRUE(tio.c_cflag & CRTSCTS);
  EXPECT_TRUE(tio.c_cflag & CREAD);
  // Linux's pty driver forces 8 data bits without parity, whatever was asked
  EXPECT_EQ(tio.c_cflag & CSIZE, static_cast<tcflag_t>(CS8));
  EXPECT_FALSE(tio.c_cflag & PARENB);
  EXPECT_EQ(cfgetospeed(&tio), static_cast<speed_t>(B9600));
  EXPECT_FALSE(tio.c_lflag & (ICANON | ECHO | ISIG));
  EXPECT_FALSE(tio.c_iflag & (ICRNL | IXON));
  EXPECT_FALSE(tio.c_oflag & OPOST);
}

TEST(SerialPort, PseudoTerminalIgnoresAnUnusualBaudRate) {
  PseudoTerminal terminal = OpenTerminal();
  PortSettings settings;
  settings.baud_rate = 250000;  // no termios constant; a pty has no speed anyway
  auto port = OpenSerialPort(terminal.slave_path(), settings);
  EXPECT_TRUE(port.ok()) << port.status().ToString();
}

TEST(PseudoTerminal, BuffersBytesWrittenBeforeAReaderOpens) {
  PseudoTerminal terminal = OpenTerminal();
  // no reader yet: the master neither fails nor hangs up
  pollfd poll_fd{terminal.master_fd(), POLLIN, 0};
  EXPECT_EQ(poll(&poll_fd, 1, 20), 0);
  ASSERT_EQ(write(terminal.master_fd(), "$H,0\n", 5), 5);

  auto port = OpenSerialPort(terminal.slave_path(), PortSettings{});
  ASSERT_TRUE(port.ok()) << port.status().ToString();
  uint8_t buffer[16];
  const Result<size_t> count = (*port)->Read(buffer, 2000);
  ASSERT_TRUE(count.ok()) << count.status().ToString();
  EXPECT_EQ(std::string(reinterpret_cast<char*>(buffer), *count), "$H,0\n");
}

TEST(PseudoTerminal, MasterSeesAHangUpOnceTheSlaveIsReleasedAndUnread) {
  PseudoTerminal terminal = OpenTerminal();
  terminal.CloseSlave();
  pollfd poll_fd{terminal.master_fd(), POLLIN, 0};
  ASSERT_EQ(poll(&poll_fd, 1, 1000), 1);
  EXPECT_TRUE(poll_fd.revents & POLLHUP);
  char byte;
  EXPECT_EQ(read(terminal.master_fd(), &byte, 1), -1);
  EXPECT_EQ(errno, EIO);
}

TEST(PseudoTerminal, MovesOwnership) {
  PseudoTerminal first = OpenTerminal();
  const std::string path = first.slave_path();
  const int master = first.master_fd();
  PseudoTerminal second(std::move(first));
  EXPECT_EQ(first.master_fd(), -1);  // NOLINT(bugprone-use-after-move): checking the move
  EXPECT_EQ(second.master_fd(), master);
  EXPECT_EQ(second.slave_path(), path);
  EXPECT_TRUE(IsPseudoTerminal(path));
}

// ---------------------------------------------------------------------------------------
// Errors a user can cause

TEST(SerialPort, MissingDeviceIsNotFoundAndNamed) {
  const auto port = OpenSerialPort("/dev/liftoff-no-such-port", PortSettings{});
  ASSERT_FALSE(port.ok());
  EXPECT_EQ(port.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(port.status().message(), HasSubstr("no such serial port: /dev/liftoff-no-such-port"));
}

TEST(SerialPort, DanglingSymlinkIsNotFound) {
  testing::ScratchDir scratch;
  fs::create_symlink(scratch / "gone", scratch / "robot");
  const auto port = OpenSerialPort((scratch / "robot").string(), PortSettings{});
  ASSERT_FALSE(port.ok());
  EXPECT_EQ(port.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(port.status().message(), HasSubstr((scratch / "robot").string()));
}

TEST(SerialPort, UnknownStableIdIsNotFoundAndNamed) {
  const auto port = OpenSerialPort("usb:dead:beef:NO-SUCH-SERIAL", PortSettings{});
  ASSERT_FALSE(port.ok());
  EXPECT_EQ(port.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(port.status().message(), HasSubstr("\"usb:dead:beef:NO-SUCH-SERIAL\""));
}

TEST(SerialPort, RegularFileIsNoSerialPort) {
  testing::ScratchDir scratch;
  testing::WriteFile(scratch / "capture.log", "text");
  const auto port = OpenSerialPort((scratch / "capture.log").string(), PortSettings{});
  ASSERT_FALSE(port.ok());
  EXPECT_EQ(port.status().code(), StatusCode::kInvalidArgument);
  EXPECT_THAT(port.status().message(), HasSubstr("not a serial port"));
}

TEST(SerialPort, TermiosOpenOfAMissingPathIsNotFound) {
  const auto port = OpenTermiosPort("/dev/pts/liftoff-missing", PortSettings{});
  ASSERT_FALSE(port.ok());
  EXPECT_EQ(port.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(port.status().message(), HasSubstr("/dev/pts/liftoff-missing"));
}

TEST(SerialPort, TermiosOpenOfANonTerminalFailsWithIo) {
  testing::ScratchDir scratch;
  testing::WriteFile(scratch / "capture.log", "text");
  const auto port = OpenTermiosPort(scratch / "capture.log", PortSettings{});
  ASSERT_FALSE(port.ok());
  EXPECT_EQ(port.status().code(), StatusCode::kIo);
  EXPECT_THAT(port.status().message(), HasSubstr("capture.log: not a terminal"));
}

TEST(SerialPort, RefusesTheActiveConsoleUnlessAllowed) {
  PseudoTerminal terminal = OpenTerminal();
  testing::ScratchDir scratch;
  const fs::path console_list = ConsoleListNaming(scratch, terminal.slave_path());
  fs::create_symlink(terminal.slave_path(), scratch / "innocent-looking");

  // by its path and through a symlink
  for (const std::string& name : {terminal.slave_path(), (scratch / "innocent-looking").string()}) {
    const auto refused = OpenSerialPort(name, PortSettings{}, console_list);
    ASSERT_FALSE(refused.ok()) << name;
    EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
    EXPECT_THAT(refused.status().message(), HasSubstr(name + " is this machine's active console"));
    EXPECT_THAT(refused.status().message(), HasSubstr("allow_console"));
  }

  PortSettings allowed;
  allowed.allow_console = true;
  EXPECT_TRUE(OpenSerialPort(terminal.slave_path(), allowed, console_list).ok());
  // no console list (no sysfs): nothing but /dev/console is refused
  EXPECT_TRUE(OpenSerialPort(terminal.slave_path(), PortSettings{}, scratch / "absent").ok());
}

// ---------------------------------------------------------------------------------------
// Listing

TEST(ListPorts, ListsRealDevicesOnly) {
  // reads sysfs only; nothing listed is opened here
  const Result<std::vector<PortInfo>> ports = ListPorts();
  ASSERT_TRUE(ports.ok()) << ports.status().ToString();
  PseudoTerminal terminal = OpenTerminal();
  const Result<std::vector<PortInfo>> again = ListPorts();
  ASSERT_TRUE(again.ok());
  for (const PortInfo& port : *again) {
    EXPECT_EQ(port.name.rfind("/dev/", 0), 0u) << port.name;
    EXPECT_NE(port.name, terminal.slave_path());
    EXPECT_NE(port.name.rfind("/dev/pts/", 0), 0u) << port.name;
    EXPECT_FALSE(port.stable_id.empty()) << port.name;
    EXPECT_THAT((std::vector<std::string>{"usb", "native", "bluetooth"}),
                ::testing::Contains(port.transport));
  }
}

TEST(ListPorts, FormatsATableWithUsbIdsAndStableIds) {
  PortInfo arduino;
  arduino.name = "/dev/ttyACM0";
  arduino.description = "Arduino Uno";
  arduino.transport = "usb";
  arduino.usb_vendor_id = 0x2341;
  arduino.usb_product_id = 0x43;
  arduino.serial_number = "8573531";
  arduino.stable_id = "usb:2341:0043:8573531";
  PortInfo uart;
  uart.name = "/dev/ttyS0";
  uart.description = "ttyS0";
  uart.transport = "native";
  uart.stable_id = "/dev/ttyS0";
  uart.is_console = true;

  EXPECT_EQ(FormatPortList({arduino, uart}),
            "device        description      usb id     serial number  stable id\n"
            "/dev/ttyACM0  Arduino Uno      2341:0043  8573531        usb:2341:0043:8573531\n"
            "/dev/ttyS0    ttyS0 (console)  -          -              /dev/ttyS0\n");
  EXPECT_EQ(FormatPortList({}), "no serial ports found\n");
}

}  // namespace
}  // namespace liftoff::capture
