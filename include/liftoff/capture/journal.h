// The raw journal of a capture: every byte received from the controller, in the chunks
// the port delivered, each with the host time it arrived. It is written before any byte
// is parsed, so whatever the parser made of a stream can always be checked, and the
// controller log rebuilt (ReplayJournal runs the very parsing of live capture).
//
// File layout (docs/cli.md, `liftoff journal`); integers little-endian:
//   "LFJ1"                       magic and version
//   uint32 header_bytes          then that many bytes of UTF-8 "key: value\n" lines:
//                                port, settings, start_time_ns, writer
//   records, until the end of the file:
//     int64  host_time_ns        host clock (Unix epoch) when the chunk arrived
//     uint32 length_and_kind     bits 0..27: payload length; bits 28..31: record kind
//                                (0 received bytes, so a plain chunk is [time][length]
//                                [bytes]; 1 bytes sent; 2 link lost; 3 link restored)
//     bytes  payload             the bytes (link records: a short note for people)
// Append-only: a crash leaves at most a cut-off last record, which readers tolerate and
// report.
#pragma once

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/controller_log.h"
#include "liftoff/core/status.h"
#include "liftoff/core/version.h"

namespace liftoff::capture {

/// What the journal's header says about the capture.
struct JournalHeader {
  /// Port the bytes came from, as named by the user ("/dev/ttyACM0", a symlink).
  std::string port;
  /// Port settings as text ("115200 8N1").
  std::string settings;
  /// Host time the capture began, ns since the Unix epoch.
  int64_t start_time_ns = 0;
  /// Program and version that wrote the journal.
  std::string writer = std::string("liftoff ") + kVersion;
};

/// What a journal record holds.
enum class JournalRecordKind : uint8_t {
  kReceived = 0,      ///< bytes received from the controller
  kSent = 1,          ///< bytes the host sent to the controller (commands)
  kLinkLost = 2,      ///< the port went away (unplugged); payload: a note
  kLinkRestored = 3,  ///< the port was reopened; payload: a note
};

/// "received", "sent", "link lost", "link restored".
std::string_view JournalRecordKindName(JournalRecordKind kind);

/// One record of a journal.
struct JournalChunk {
  /// Host clock when the bytes arrived (or were sent), ns since the Unix epoch.
  int64_t host_time_ns = 0;
  JournalRecordKind kind = JournalRecordKind::kReceived;
  /// The bytes as received (a note for link records).
  std::string bytes;
};

/// Appends records to a journal; memory stays flat. Not thread-safe.
class JournalWriter {
 public:
  struct Options {
    /// Buffered bytes are handed to the operating system whenever this many are
    /// buffered, bytes. Flushing on a timer is the owner's job (call Flush(): a capture
    /// does so every flush_interval_ms), so a crash of the process loses nothing older.
    size_t flush_bytes = 64 * 1024;
    /// Replace an existing file. Off: Open fails with kInvalidArgument when the path
    /// exists (checked by the creation itself, O_EXCL, so two writers cannot both win).
    bool replace_existing = true;

    Status Validate() const;
  };

  JournalWriter() = default;
  JournalWriter(const JournalWriter&) = delete;
  JournalWriter& operator=(const JournalWriter&) = delete;
  ~JournalWriter();  ///< closes (flushes) when still open

  /// Creates (truncates) `path`, creating its folder, and writes the header at once.
  /// kIo naming the file on failure, kInvalidArgument for bad options and for an
  /// existing file when not options.replace_existing.
  Status Open(const std::filesystem::path& path, const JournalHeader& header,
              const Options& options);
  Status Open(const std::filesystem::path& path, const JournalHeader& header) {
    return Open(path, header, Options{});
  }
  /// Appends one record (received bytes unless told otherwise). Empty received chunks
  /// are skipped. Flushes when the byte threshold is reached.
  Status Append(std::span<const uint8_t> bytes, int64_t host_time_ns,
                JournalRecordKind kind = JournalRecordKind::kReceived);
  /// Appends a link record with a note for people ("read failed: device gone").
  Status AppendNote(JournalRecordKind kind, std::string_view note, int64_t host_time_ns);
  /// Hands every buffered byte to the operating system.
  Status Flush();
  /// Flushes, syncs to the disk and closes. Closing a closed writer is a no-op.
  Status Close();

  bool is_open() const { return fd_ >= 0; }
  const std::filesystem::path& path() const { return path_; }
  /// Payload bytes of received records written so far.
  int64_t bytes_received() const { return bytes_received_; }

 private:
  Status WriteBuffered();

  std::filesystem::path path_;
  Options options_;
  int fd_ = -1;
  std::string buffer_;
  int64_t bytes_received_ = 0;
};

/// Reads a journal record by record; memory stays flat in the journal's length.
class JournalReader {
 public:
  JournalReader() = default;
  JournalReader(const JournalReader&) = delete;
  JournalReader& operator=(const JournalReader&) = delete;
  ~JournalReader();

  /// Opens `path` and reads its header. kNotFound for a missing file, kParse (naming
  /// the file and byte offset) when it is not a journal or its header is cut off,
  /// kUnsupported for another version ("LFJ2").
  Status Open(const std::filesystem::path& path);
  const JournalHeader& header() const { return header_; }

  /// The next record; false at the end of the file or at a cut-off last record (then
  /// truncated() is true). A record with an unknown kind or a length over 16 MiB (more
  /// than any writer puts in one record: a corrupt journal) is a kParse error naming the
  /// byte offset, reported through status().
  bool Next(JournalChunk& chunk);
  /// The error that stopped Next, if any (OK at a clean or truncated end).
  const Status& status() const { return status_; }
  /// Whether the last record was cut off (a capture that died mid-write).
  bool truncated() const { return truncated_; }
  /// Bytes of the cut-off last record that were skipped.
  int64_t truncated_bytes() const { return truncated_bytes_; }
  /// Byte offset of the next record.
  int64_t offset() const { return offset_; }

 private:
  std::filesystem::path path_;
  std::FILE* file_ = nullptr;
  JournalHeader header_;
  Status status_;
  bool truncated_ = false;
  int64_t truncated_bytes_ = 0;
  int64_t offset_ = 0;
};

/// What replaying a journal found besides the log.
struct JournalReplay {
  /// The controller log, as live capture would have written it (the header's source
  /// reads "replay <journal> (capture <port>)").
  ControllerLog log;
  /// Records and received bytes read.
  int64_t records = 0;
  int64_t bytes = 0;
  /// Whether the last record was cut off, and how many bytes of it were skipped.
  bool truncated = false;
  int64_t truncated_bytes = 0;
  /// Parser counters: frames accepted, checksum failures, malformed lines, garbage
  /// bytes, sequence gaps and missing frames, frames dropped as duplicates.
  int64_t frames = 0;
  int64_t checksum_errors = 0;
  int64_t malformed_frames = 0;
  int64_t garbage_bytes = 0;
  int64_t gaps = 0;
  int64_t missing_frames = 0;
  int64_t duplicates = 0;

  /// "trial.journal: 1.2 MB in 4100 records, 30000 frames (2 checksum failures, ...)".
  std::string Brief() const;
};

/// Rebuilds the controller log from a journal with the parsing of live capture (samples,
/// events, gaps, reconnects, dropped duplicates alike). A cut-off last record is
/// tolerated and reported. Errors: those of JournalReader::Open and Next.
Result<JournalReplay> ReplayJournal(const std::filesystem::path& path,
                                    const Calibration& calibration);

/// How DumpJournal prints.
struct JournalDumpOptions {
  /// Records to print at most (0: all).
  int64_t max_records = 0;
  /// Print received bytes as text (frames are text lines; other bytes as \xNN) rather
  /// than as hexadecimal.
  bool text = true;

  /// kInvalidArgument "max_records: expected >= 0, got -1".
  Status Validate() const;
};

/// The journal for people, written to `out` as it is read: its header, then one line per
/// record with its host time (seconds since the capture began), kind and length, then the
/// bytes (text frames read as they are), and a closing line that reports a cut-off last
/// record. Errors: options.Validate()'s, then those of JournalReader::Open and Next.
Status DumpJournal(const std::filesystem::path& path, const JournalDumpOptions& options,
                   std::ostream& out);

}  // namespace liftoff::capture
