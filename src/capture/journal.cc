#include "liftoff/capture/journal.h"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <ostream>

#include "liftoff/capture/capture_session.h"
#include "liftoff/core/file.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"

namespace liftoff::capture {
namespace {

constexpr char kMagic[4] = {'L', 'F', 'J', '1'};
constexpr size_t kRecordHeaderBytes = 12;
constexpr uint32_t kLengthMask = 0x0FFF'FFFFu;
constexpr int kKindShift = 28;
constexpr uint32_t kMaxHeaderBytes = 64 * 1024;
constexpr int kKindCount = 4;
// Longest record payload a reader accepts; writers split longer chunks.
constexpr uint32_t kMaxRecordBytes = 16 * 1024 * 1024;

void PutU32(std::string& out, uint32_t value) {
  for (int i = 0; i < 4; ++i) out += static_cast<char>((value >> (8 * i)) & 0xFF);
}

void PutI64(std::string& out, int64_t value) {
  const auto bits = static_cast<uint64_t>(value);
  for (int i = 0; i < 8; ++i) out += static_cast<char>((bits >> (8 * i)) & 0xFF);
}

uint32_t GetU32(const uint8_t* in) {
  uint32_t value = 0;
  for (int i = 3; i >= 0; --i) value = (value << 8) | in[i];
  return value;
}

int64_t GetI64(const uint8_t* in) {
  uint64_t bits = 0;
  for (int i = 7; i >= 0; --i) bits = (bits << 8) | in[i];
  return static_cast<int64_t>(bits);
}

std::string Errno() { return std::strerror(errno); }

std::string HeaderText(const JournalHeader& header) {
  const auto one_line = [](std::string text) {
    for (char& c : text) {
      if (c == '\n' || c == '\r') c = ' ';
    }
    return text;
  };
  return "port: " + one_line(header.port) + "\nsettings: " + one_line(header.settings) +
         "\nstart_time_ns: " + std::to_string(header.start_time_ns) +
         "\nwriter: " + one_line(header.writer) + "\n";
}

// "key: value" lines; unknown keys are skipped so later versions can add some.
Status ParseHeaderText(const std::string& text, const std::string& where, JournalHeader& header) {
  size_t begin = 0;
  while (begin < text.size()) {
    size_t end = text.find('\n', begin);
    if (end == std::string::npos) end = text.size();
    const std::string_view line(text.data() + begin, end - begin);
    begin = end + 1;
    const size_t colon = line.find(": ");
    if (colon == std::string_view::npos) continue;
    const std::string_view key = line.substr(0, colon);
    const std::string value(line.substr(colon + 2));
    if (key == "port") header.port = value;
    if (key == "settings") header.settings = value;
    if (key == "writer") header.writer = value;
    if (key == "start_time_ns") {
      const auto [ptr, error] =
          std::from_chars(value.data(), value.data() + value.size(), header.start_time_ns);
      if (error != std::errc() || ptr != value.data() + value.size()) {
        return ParseError(where + ": header start_time_ns: expected an integer, got \"" + value +
                          "\"");
      }
    }
  }
  return Status::Ok();
}

// Received bytes for people: text as is, other bytes as \xNN, one frame per line.
void PrintText(std::string_view bytes, std::ostream& out) {
  bool line_start = true;
  for (const char c : bytes) {
    if (line_start) out << "  ";
    line_start = false;
    const auto byte = static_cast<unsigned char>(c);
    if (c == '\n') {
      out << '\n';
      line_start = true;
    } else if (c == '\r') {
      out << "\\r";
    } else if (byte < 0x20 || byte >= 0x7f || c == '\\') {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\x%02x", byte);
      out << escaped;
    } else {
      out << c;
    }
  }
  if (!line_start) out << '\n';
}

void PrintHex(std::string_view bytes, std::ostream& out) {
  for (size_t i = 0; i < bytes.size(); i += 16) {
    out << " ";
    for (size_t j = i; j < bytes.size() && j < i + 16; ++j) {
      char hex[4];
      std::snprintf(hex, sizeof hex, " %02x", static_cast<unsigned char>(bytes[j]));
      out << hex;
    }
    out << '\n';
  }
}

}  // namespace

std::string_view JournalRecordKindName(JournalRecordKind kind) {
  switch (kind) {
    case JournalRecordKind::kReceived: return "received";
    case JournalRecordKind::kSent: return "sent";
    case JournalRecordKind::kLinkLost: return "link lost";
    case JournalRecordKind::kLinkRestored: return "link restored";
  }
  return "unknown";
}

// ---------------------------------------------------------------------------------------
// writer

Status JournalWriter::Options::Validate() const {
  if (flush_bytes == 0) return InvalidArgumentError("journal flush_bytes: expected > 0, got 0");
  return Status::Ok();
}

JournalWriter::~JournalWriter() {
  if (is_open()) (void)Close();
}

Status JournalWriter::Open(const std::filesystem::path& path, const JournalHeader& header,
                           const Options& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  if (is_open()) LIFTOFF_RETURN_IF_ERROR(Close());
  LIFTOFF_RETURN_IF_ERROR(CreateParentFolder(path));
  path_ = path;
  options_ = options;
  bytes_received_ = 0;
  const int replace = options.replace_existing ? O_TRUNC : O_EXCL;
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | replace, 0644);
  if (fd_ < 0 && errno == EEXIST && !options.replace_existing) {
    return InvalidArgumentError(path.string() + ": exists; expected a new journal");
  }
  if (fd_ < 0) return IoError(path.string() + ": cannot open for writing: " + Errno());

  // the header reaches the disk at once: the journal names its port even if nothing came
  const std::string text = HeaderText(header);
  buffer_.assign(kMagic, sizeof kMagic);
  PutU32(buffer_, static_cast<uint32_t>(text.size()));
  buffer_ += text;
  return Flush();
}

Status JournalWriter::Append(std::span<const uint8_t> bytes, int64_t host_time_ns,
                             JournalRecordKind kind) {
  if (!is_open()) return IoError(path_.string() + ": journal is not open");
  if (bytes.empty() && kind == JournalRecordKind::kReceived) return Status::Ok();
  // longer chunks are split: the length field holds 28 bits
  size_t offset = 0;
  do {
    const size_t length = std::min<size_t>(bytes.size() - offset, kMaxRecordBytes);
    PutI64(buffer_, host_time_ns);
    PutU32(buffer_, static_cast<uint32_t>(length) | (static_cast<uint32_t>(kind) << kKindShift));
    buffer_.append(reinterpret_cast<const char*>(bytes.data() + offset), length);
    offset += length;
  } while (offset < bytes.size());
  if (kind == JournalRecordKind::kReceived) bytes_received_ += static_cast<int64_t>(bytes.size());

  // hand to the OS when enough is buffered (the owner flushes on its timer)
  if (buffer_.size() >= options_.flush_bytes) return Flush();
  return Status::Ok();
}

Status JournalWriter::AppendNote(JournalRecordKind kind, std::string_view note,
                                 int64_t host_time_ns) {
  return Append(std::span(reinterpret_cast<const uint8_t*>(note.data()), note.size()), host_time_ns,
                kind);
}

Status JournalWriter::WriteBuffered() {
  size_t written = 0;
  while (written < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + written, buffer_.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      const std::string reason = Errno();
      buffer_.erase(0, written);
      return IoError(path_.string() + ": write failed: " + reason);
    }
    written += static_cast<size_t>(n);
  }
  buffer_.clear();
  return Status::Ok();
}

Status JournalWriter::Flush() {
  if (!is_open()) return Status::Ok();
  return WriteBuffered();
}

Status JournalWriter::Close() {
  if (!is_open()) return Status::Ok();
  Status status = Flush();
  if (::fsync(fd_) != 0 && status.ok() && errno != EINVAL) {
    status = IoError(path_.string() + ": sync failed: " + Errno());
  }
  if (::close(fd_) != 0 && status.ok())
    status = IoError(path_.string() + ": close failed: " + Errno());
  fd_ = -1;
  buffer_.clear();
  return status;
}

// ---------------------------------------------------------------------------------------
// reader

JournalReader::~JournalReader() {
  if (file_ != nullptr) std::fclose(file_);
}

Status JournalReader::Open(const std::filesystem::path& path) {
  if (file_ != nullptr) {
    std::fclose(file_);
    file_ = nullptr;  // a failed Open below must not leave a dangling handle to close again
  }
  path_ = path;
  header_ = JournalHeader{};
  status_ = Status::Ok();
  truncated_ = false;
  truncated_bytes_ = 0;
  std::error_code error;
  if (!std::filesystem::exists(path, error)) return NotFoundError(path.string() + ": no such file");
  if (std::filesystem::is_directory(path, error)) {
    return InvalidArgumentError(path.string() + ": is a folder, expected a journal file");
  }
  file_ = std::fopen(path.c_str(), "rb");
  if (file_ == nullptr) return IoError(path.string() + ": cannot open: " + Errno());

  // magic, header length, header text
  uint8_t start[8];
  const size_t got = std::fread(start, 1, sizeof start, file_);
  if (got < 4 || std::memcmp(start, kMagic, 3) != 0) {
    return ParseError(path.string() + ": byte 0: expected the journal magic \"LFJ1\", got " +
                      (got < 4 ? "end of file" : "\"" + std::string(start, start + 4) + "\""));
  }
  if (start[3] != '1') {
    return UnsupportedError(path.string() + ": journal version \"" + std::string(start, start + 4) +
                            "\" is not supported; this build reads LFJ1");
  }
  if (got < sizeof start) {
    return ParseError(path.string() + ": byte 4: header length cut off (the file ends at byte " +
                      std::to_string(got) + ")");
  }
  const uint32_t header_bytes = GetU32(start + 4);
  if (header_bytes > kMaxHeaderBytes) {
    return ParseError(path.string() + ": byte 4: header length " + std::to_string(header_bytes) +
                      " exceeds " + std::to_string(kMaxHeaderBytes));
  }
  std::string text(header_bytes, '\0');
  if (std::fread(text.data(), 1, header_bytes, file_) != header_bytes) {
    return ParseError(path.string() + ": byte 8: header cut off (expected " +
                      std::to_string(header_bytes) + " bytes)");
  }
  offset_ = 8 + static_cast<int64_t>(header_bytes);
  return ParseHeaderText(text, path.string(), header_);
}

bool JournalReader::Next(JournalChunk& chunk) {
  if (file_ == nullptr || !status_.ok() || truncated_) return false;
  uint8_t head[kRecordHeaderBytes];
  const size_t got = std::fread(head, 1, sizeof head, file_);
  if (got == 0) return false;
  if (got < sizeof head) {
    truncated_ = true;
    truncated_bytes_ = static_cast<int64_t>(got);
    return false;
  }
  const uint32_t length_and_kind = GetU32(head + 8);
  const uint32_t kind = length_and_kind >> kKindShift;
  const uint32_t length = length_and_kind & kLengthMask;
  if (kind >= kKindCount) {
    status_ = ParseError(path_.string() + ": byte " + std::to_string(offset_) +
                         ": unknown record kind " + std::to_string(kind) + " (expected 0..3)");
    return false;
  }
  // a corrupt length must not make us allocate up to 256 MiB: writers split chunks
  // longer than kMaxRecordBytes (a plausible length past the end of the file is a
  // cut-off last record, found by the read below)
  if (length > kMaxRecordBytes) {
    status_ = ParseError(path_.string() + ": byte " + std::to_string(offset_) + ": record length " +
                         std::to_string(length) + " exceeds " + std::to_string(kMaxRecordBytes) +
                         " (corrupt journal)");
    return false;
  }
  chunk.host_time_ns = GetI64(head);
  chunk.kind = static_cast<JournalRecordKind>(kind);
  chunk.bytes.resize(length);
  const size_t payload = std::fread(chunk.bytes.data(), 1, length, file_);
  if (payload < length) {
    truncated_ = true;
    truncated_bytes_ = static_cast<int64_t>(sizeof head + payload);
    return false;
  }
  offset_ += static_cast<int64_t>(sizeof head + length);
  return true;
}

// ---------------------------------------------------------------------------------------
// replay and dump

std::string JournalReplay::Brief() const {
  std::string brief = log.report.source.filename().string() + ": " + Plural(bytes, "byte") +
                      " in " + Plural(records, "record") + ", " + Plural(frames, "frame") + " (" +
                      Plural(checksum_errors, "checksum failure") + ", " +
                      std::to_string(malformed_frames) + " malformed, " +
                      Plural(garbage_bytes, "garbage byte") + ", " + Plural(gaps, "gap") + ", " +
                      Plural(duplicates, "duplicate") + " dropped)";
  if (truncated) brief += "; last record cut off (" + Plural(truncated_bytes, "byte") + " skipped)";
  return brief;
}

Result<JournalReplay> ReplayJournal(const std::filesystem::path& path,
                                    const Calibration& calibration) {
  JournalReader reader;
  LIFTOFF_RETURN_IF_ERROR(reader.Open(path));

  // every record through the decoder of live capture
  JournalReplay replay;
  StreamDecoder decoder(calibration);
  std::optional<wire::CommandFrame> start;
  std::vector<LogRow> rows;
  JournalChunk chunk;
  while (reader.Next(chunk)) {
    ++replay.records;
    const std::span bytes(reinterpret_cast<const uint8_t*>(chunk.bytes.data()), chunk.bytes.size());
    switch (chunk.kind) {
      case JournalRecordKind::kReceived:
        replay.bytes += static_cast<int64_t>(bytes.size());
        decoder.Feed(bytes, chunk.host_time_ns, rows);
        break;
      case JournalRecordKind::kSent: {
        // the start command's parameters go into the header, as in live capture
        std::string_view line(chunk.bytes);
        if (!line.empty() && line.back() == '\n') line.remove_suffix(1);
        wire::Frame frame;
        if (wire::DecodeLine(line.data(), line.size(), &frame) == wire::DecodeError::kOk &&
            frame.type == wire::FrameType::kCommand &&
            frame.command.command == wire::CommandKind::kStart) {
          start = frame.command;
        }
        break;
      }
      case JournalRecordKind::kLinkLost: decoder.LinkLost(chunk.host_time_ns); break;
      case JournalRecordKind::kLinkRestored: decoder.LinkRestored(chunk.host_time_ns); break;
    }
  }
  LIFTOFF_RETURN_IF_ERROR(reader.status());
  decoder.Finish(rows);

  // the log
  ControllerLog& log = replay.log;
  log.header = CaptureLogHeader(
      calibration, "replay " + path.filename().string() + " (capture " + reader.header().port + ")",
      reader.header().settings, path.filename().string(), decoder.device_header(), start);
  for (LogRow& row : rows) {
    if (auto* sample = std::get_if<LogSample>(&row)) {
      log.samples.push_back(std::move(*sample));
    } else {
      log.events.push_back(std::move(std::get<LogEvent>(row)));
    }
  }
  log.report.source = path;
  log.report.format = "liftoff-journal";
  log.report.samples = static_cast<int64_t>(log.samples.size());
  log.report.events = static_cast<int64_t>(log.events.size());
  log.report.lines_total = log.report.samples + log.report.events;

  // counters
  const ParserStats& parser = decoder.parser_stats();
  replay.truncated = reader.truncated();
  replay.truncated_bytes = reader.truncated_bytes();
  replay.frames = parser.frames;
  replay.checksum_errors = parser.checksum_errors;
  replay.malformed_frames = parser.malformed_frames;
  replay.garbage_bytes = parser.garbage_bytes;
  replay.gaps = decoder.counters().gaps;
  replay.missing_frames = decoder.counters().missing_frames;
  replay.duplicates = decoder.counters().duplicates;
  return replay;
}

Status JournalDumpOptions::Validate() const {
  if (max_records >= 0) return Status::Ok();
  return InvalidArgumentError("max_records: expected >= 0, got " + std::to_string(max_records));
}

Status DumpJournal(const std::filesystem::path& path, const JournalDumpOptions& options,
                   std::ostream& out) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  JournalReader reader;
  LIFTOFF_RETURN_IF_ERROR(reader.Open(path));
  const JournalHeader& header = reader.header();
  out << "journal " << path.string() << "\nport: " << header.port
      << "\nsettings: " << header.settings << "\nstart_time_ns: " << header.start_time_ns
      << "\nwriter: " << header.writer << "\n";

  // one line per record, times in seconds since the capture began
  int64_t records = 0;
  int64_t bytes = 0;
  JournalChunk chunk;
  while (reader.Next(chunk)) {
    ++records;
    if (chunk.kind == JournalRecordKind::kReceived)
      bytes += static_cast<int64_t>(chunk.bytes.size());
    if (options.max_records > 0 && records > options.max_records) continue;
    const int64_t since_start_ns = chunk.host_time_ns - header.start_time_ns;
    out << (since_start_ns < 0 ? "-" : "+") << FormatSeconds(std::abs(since_start_ns), 6) << " s  "
        << JournalRecordKindName(chunk.kind);
    if (chunk.kind == JournalRecordKind::kLinkLost ||
        chunk.kind == JournalRecordKind::kLinkRestored) {
      out << ": " << chunk.bytes << '\n';
      continue;
    }
    out << ' ' << Plural(static_cast<int64_t>(chunk.bytes.size()), "byte") << '\n';
    if (options.text) {
      PrintText(chunk.bytes, out);
    } else {
      PrintHex(chunk.bytes, out);
    }
  }
  LIFTOFF_RETURN_IF_ERROR(reader.status());
  if (options.max_records > 0 && records > options.max_records) {
    out << "... " << Plural(records - options.max_records, "more record") << '\n';
  }
  out << Plural(records, "record") << ", " << Plural(bytes, "byte") << " received";
  if (reader.truncated()) {
    out << "; the last record is cut off (" << Plural(reader.truncated_bytes(), "byte")
        << " skipped: the capture stopped mid-write)";
  }
  out << '\n';
  return Status::Ok();
}

}  // namespace liftoff::capture
