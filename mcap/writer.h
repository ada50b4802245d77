#pragma once

#include <cstdint>
#include <map>
#include <ostream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "mcap/crc32.h"

/// A writer of MCAP files (MCAP format specification, major version 0,
/// mcap.dev/spec): magic, header, a data section of chunks (each followed
/// by its message indexes), data end with the data section's CRC, a summary
/// section (schemas, channels, statistics, chunk indexes), its summary
/// offsets, the footer with the summary's CRC, and the closing magic. It
/// knows nothing of linesim: schemas, channels and message bytes are the
/// caller's.
namespace linesim::mcap {

/// Record opcodes (specification, "Records").
enum class Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

/// The eight bytes every MCAP file starts and ends with: 0x89 "MCAP" and the
/// major version '0', then "\r\n".
inline constexpr std::string_view kMagic{"\x89MCAP0\r\n", 8};

/// A chunk's compression: none, zstd (a zstd frame), or lz4 (an LZ4 frame,
/// the specification's "lz4").
enum class Compression { kNone, kZstd, kLz4 };

struct WriterOptions {
  std::string profile;            // header profile ("" : none of the well-known ones)
  std::string library = "linesim";  // header library: what wrote the file
  /// lz4: about four times cheaper than zstd's level 1 on linesim's JSON,
  /// for files about 1.5 times larger (measured on cross_line's run.mcap).
  Compression compression = Compression::kLz4;
  /// A chunk is closed once its uncompressed records reach this size.
  std::size_t chunk_size = 1 << 20;
  /// zstd's level: 1 is its fastest standard level (ratio about 3 on
  /// linesim's JSON, against 3.3 at its default 3, in half the time).
  int zstd_level = 1;
};

/// The most bytes `bytes` of records take in a chunk compressed with
/// `compression` (the compressor's own worst case: incompressible input).
std::uint64_t CompressedBound(Compression compression, std::uint64_t bytes);

/// Little-endian encoders of the specification's field types.
void PutU8(std::string& out, std::uint8_t v);
void PutU16(std::string& out, std::uint16_t v);
void PutU32(std::string& out, std::uint32_t v);
void PutU64(std::string& out, std::uint64_t v);
/// String: uint32 byte length, then the UTF-8 bytes.
void PutString(std::string& out, std::string_view s);
/// A record: opcode, uint64 content length, content.
void PutRecord(std::string& out, Opcode op, std::string_view content);

class Writer {
 public:
  /// Writes the magic and the header at once. `out` must stay open until
  /// Close(); a failed stream shows in out.fail() afterwards.
  Writer(std::ostream& out, WriterOptions options = {});
  ~Writer();
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  /// A schema (ids count from 1; 0 means "no schema"). `encoding`: e.g.
  /// "jsonschema"; `data`: the schema text.
  std::uint16_t AddSchema(std::string name, std::string encoding, std::string data);
  /// A channel on `schema_id` (0: none). Ids count from 0.
  std::uint16_t AddChannel(std::uint16_t schema_id, std::string topic,
                           std::string message_encoding,
                           std::vector<std::pair<std::string, std::string>> metadata = {});
  /// One message; times in nanoseconds. A channel's schema and the channel
  /// itself are written into the data section before its first message.
  void WriteMessage(std::uint16_t channel_id, std::uint64_t log_time, std::uint64_t publish_time,
                    std::string_view data);
  /// A metadata record: `name` and its key-value pairs (strings). Written in
  /// the data section after the last chunk, indexed in the summary (a
  /// Metadata Index record) and counted in the statistics.
  void AddMetadata(std::string name, std::vector<std::pair<std::string, std::string>> metadata);
  /// Closes the last chunk and writes the metadata, data end, summary,
  /// summary offsets, footer and magic. Called by the destructor if not
  /// before.
  void Close();

  std::uint64_t bytes_written() const { return offset_; }
  std::uint64_t message_count() const { return message_count_; }
  std::uint32_t chunk_count() const { return static_cast<std::uint32_t>(chunk_indexes_.size()); }
  std::uint16_t schema_count() const { return static_cast<std::uint16_t>(schemas_.size()); }
  std::uint16_t channel_count() const { return static_cast<std::uint16_t>(channels_.size()); }
  /// The content's size of schema `id` (from 1) and of channel `id`.
  std::uint64_t SchemaBytes(std::uint16_t id) const { return SchemaContent(id).size(); }
  std::uint64_t ChannelBytes(std::uint16_t id) const { return ChannelContent(id).size(); }

 private:
  struct Schema {
    std::string name, encoding, data;
    bool written = false;
  };
  struct Channel {
    std::uint16_t schema_id;
    std::string topic, message_encoding;
    std::vector<std::pair<std::string, std::string>> metadata;
    bool written = false;
    std::uint32_t sequence = 0;
    std::uint64_t message_count = 0;
    /// This chunk's index entries: (log time, offset in the chunk's records).
    std::vector<std::pair<std::uint64_t, std::uint64_t>> index;
  };
  struct ChunkIndex {
    std::uint64_t start_time, end_time, offset, length;
    std::map<std::uint16_t, std::uint64_t> message_index_offsets;
    std::uint64_t message_index_length, compressed_size, uncompressed_size;
  };

  void Emit(std::string_view bytes);
  std::string SchemaContent(std::uint16_t id) const;
  std::string ChannelContent(std::uint16_t id) const;
  void FlushChunk();

  std::ostream& out_;
  WriterOptions options_;
  std::uint64_t offset_ = 0;
  Crc32 crc_;  // the data section's, then the summary's
  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::string chunk_;       // the open chunk's records, uncompressed
  std::string compressed_;  // scratch for a chunk's compressed records
  std::string scratch_;     // scratch for a record's content
  bool chunk_has_messages_ = false;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0;
  std::vector<ChunkIndex> chunk_indexes_;
  struct Metadata {
    std::string name;
    std::vector<std::pair<std::string, std::string>> entries;
    std::uint64_t offset = 0, length = 0;  // of its record, once written
  };
  std::vector<Metadata> metadata_;
  std::uint64_t message_count_ = 0;
  std::uint64_t first_time_ = 0, last_time_ = 0;
  bool closed_ = false;
};

}  // namespace linesim::mcap
