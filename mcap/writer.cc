#include "mcap/writer.h"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <stdexcept>

namespace linesim::mcap {

void PutU8(std::string& out, std::uint8_t v) { out.push_back(static_cast<char>(v)); }

void PutU16(std::string& out, std::uint16_t v) {
  for (int k = 0; k < 2; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xFFu));
}

void PutU32(std::string& out, std::uint32_t v) {
  for (int k = 0; k < 4; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xFFu));
}

void PutU64(std::string& out, std::uint64_t v) {
  for (int k = 0; k < 8; ++k) out.push_back(static_cast<char>((v >> (8 * k)) & 0xFFu));
}

void PutString(std::string& out, std::string_view s) {
  PutU32(out, static_cast<std::uint32_t>(s.size()));
  out.append(s);
}

void PutRecord(std::string& out, Opcode op, std::string_view content) {
  PutU8(out, static_cast<std::uint8_t>(op));
  PutU64(out, content.size());
  out.append(content);
}

namespace {

// Map<K, V>: uint32 byte length of the entries, then key, value pairs.
void PutStringMap(std::string& out, const std::vector<std::pair<std::string, std::string>>& m) {
  std::string entries;
  for (const auto& [k, v] : m) {
    PutString(entries, k);
    PutString(entries, v);
  }
  PutU32(out, static_cast<std::uint32_t>(entries.size()));
  out += entries;
}

void PutU16U64Map(std::string& out, const std::map<std::uint16_t, std::uint64_t>& m) {
  PutU32(out, static_cast<std::uint32_t>(m.size() * 10));
  for (const auto& [k, v] : m) {
    PutU16(out, k);
    PutU64(out, v);
  }
}

const char* CompressionName(Compression c) {
  switch (c) {
    case Compression::kZstd:
      return "zstd";
    case Compression::kLz4:
      return "lz4";
    default:
      return "";
  }
}

}  // namespace

std::uint64_t CompressedBound(Compression compression, std::uint64_t bytes) {
  switch (compression) {
    case Compression::kZstd:
      return ZSTD_compressBound(bytes);
    case Compression::kLz4: {
      LZ4F_preferences_t prefs{};
      prefs.frameInfo.contentSize = bytes;
      return LZ4F_compressFrameBound(bytes, &prefs);
    }
    default:
      return bytes;
  }
}

Writer::Writer(std::ostream& out, WriterOptions options)
    : out_(out), options_(std::move(options)) {
  Emit(kMagic);
  std::string header;
  PutString(header, options_.profile);
  PutString(header, options_.library);
  std::string record;
  PutRecord(record, Opcode::kHeader, header);
  Emit(record);
}

Writer::~Writer() {
  try {
    Close();
  } catch (...) {
    // A destructor must not throw; Close() called explicitly reports.
  }
}

void Writer::Emit(std::string_view bytes) {
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  crc_.Update(bytes);
  offset_ += bytes.size();
}

std::uint16_t Writer::AddSchema(std::string name, std::string encoding, std::string data) {
  if (schemas_.size() >= 0xFFFEu) throw std::length_error("mcap: too many schemas");
  schemas_.push_back({std::move(name), std::move(encoding), std::move(data)});
  return static_cast<std::uint16_t>(schemas_.size());
}

std::uint16_t Writer::AddChannel(std::uint16_t schema_id, std::string topic,
                                 std::string message_encoding,
                                 std::vector<std::pair<std::string, std::string>> metadata) {
  if (schema_id > schemas_.size()) throw std::invalid_argument("mcap: unknown schema id");
  if (channels_.size() >= 0xFFFFu) throw std::length_error("mcap: too many channels");
  Channel c;
  c.schema_id = schema_id;
  c.topic = std::move(topic);
  c.message_encoding = std::move(message_encoding);
  c.metadata = std::move(metadata);
  channels_.push_back(std::move(c));
  return static_cast<std::uint16_t>(channels_.size() - 1);
}

void Writer::AddMetadata(std::string name,
                         std::vector<std::pair<std::string, std::string>> metadata) {
  if (closed_) throw std::logic_error("mcap: metadata after Close()");
  metadata_.push_back({std::move(name), std::move(metadata)});
}

std::string Writer::SchemaContent(std::uint16_t id) const {
  const Schema& s = schemas_[id - 1u];
  std::string content;
  PutU16(content, id);
  PutString(content, s.name);
  PutString(content, s.encoding);
  PutString(content, s.data);  // bytes: the same uint32 length prefix
  return content;
}

std::string Writer::ChannelContent(std::uint16_t id) const {
  const Channel& c = channels_[id];
  std::string content;
  PutU16(content, id);
  PutU16(content, c.schema_id);
  PutString(content, c.topic);
  PutString(content, c.message_encoding);
  PutStringMap(content, c.metadata);
  return content;
}

void Writer::WriteMessage(std::uint16_t channel_id, std::uint64_t log_time,
                          std::uint64_t publish_time, std::string_view data) {
  if (closed_) throw std::logic_error("mcap: message after Close()");
  if (channel_id >= channels_.size()) throw std::invalid_argument("mcap: unknown channel id");
  Channel& c = channels_[channel_id];
  if (!c.written) {
    if (c.schema_id != 0 && !schemas_[c.schema_id - 1u].written) {
      PutRecord(chunk_, Opcode::kSchema, SchemaContent(c.schema_id));
      schemas_[c.schema_id - 1u].written = true;
    }
    PutRecord(chunk_, Opcode::kChannel, ChannelContent(channel_id));
    c.written = true;
  }
  c.index.emplace_back(log_time, chunk_.size());
  PutU8(chunk_, static_cast<std::uint8_t>(Opcode::kMessage));
  PutU64(chunk_, 2 + 4 + 8 + 8 + data.size());
  PutU16(chunk_, channel_id);
  PutU32(chunk_, c.sequence++);
  PutU64(chunk_, log_time);
  PutU64(chunk_, publish_time);
  chunk_.append(data);
  ++c.message_count;
  if (message_count_ == 0) {
    first_time_ = last_time_ = log_time;
  } else {
    first_time_ = std::min(first_time_, log_time);
    last_time_ = std::max(last_time_, log_time);
  }
  ++message_count_;
  if (!chunk_has_messages_) {
    chunk_start_ = chunk_end_ = log_time;
    chunk_has_messages_ = true;
  } else {
    chunk_start_ = std::min(chunk_start_, log_time);
    chunk_end_ = std::max(chunk_end_, log_time);
  }
  if (chunk_.size() >= options_.chunk_size) FlushChunk();
}

void Writer::FlushChunk() {
  if (!chunk_has_messages_) return;
  const std::uint32_t chunk_crc = ComputeCrc32(chunk_);
  std::string_view records = chunk_;
  if (options_.compression == Compression::kZstd) {
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t n = ZSTD_compress(compressed_.data(), compressed_.size(), chunk_.data(),
                                        chunk_.size(), options_.zstd_level);
    if (ZSTD_isError(n)) {
      throw std::runtime_error(std::string("mcap: zstd: ") + ZSTD_getErrorName(n));
    }
    compressed_.resize(n);
    records = compressed_;
  } else if (options_.compression == Compression::kLz4) {
    // The frame's defaults (64 KiB linked blocks, no checksums: the chunk
    // has its CRC), its content size recorded.
    LZ4F_preferences_t prefs{};
    prefs.frameInfo.contentSize = chunk_.size();
    compressed_.resize(LZ4F_compressFrameBound(chunk_.size(), &prefs));
    const std::size_t n = LZ4F_compressFrame(compressed_.data(), compressed_.size(),
                                             chunk_.data(), chunk_.size(), &prefs);
    if (LZ4F_isError(n)) {
      throw std::runtime_error(std::string("mcap: lz4: ") + LZ4F_getErrorName(n));
    }
    compressed_.resize(n);
    records = compressed_;
  }
  ChunkIndex index;
  index.start_time = chunk_start_;
  index.end_time = chunk_end_;
  index.offset = offset_;
  index.compressed_size = records.size();
  index.uncompressed_size = chunk_.size();

  // The chunk record, written in parts: its records are the bulk.
  const char* compression = CompressionName(options_.compression);
  scratch_.clear();
  PutU64(scratch_, chunk_start_);
  PutU64(scratch_, chunk_end_);
  PutU64(scratch_, chunk_.size());
  PutU32(scratch_, chunk_crc);
  PutString(scratch_, compression);
  PutU64(scratch_, records.size());
  std::string head;
  PutU8(head, static_cast<std::uint8_t>(Opcode::kChunk));
  PutU64(head, scratch_.size() + records.size());
  head += scratch_;
  Emit(head);
  Emit(records);
  index.length = offset_ - index.offset;

  // Its message indexes, one per channel with messages in it, by channel id;
  // each channel's entries in log-time order (stable: equal times keep the
  // order written).
  const std::uint64_t indexes_start = offset_;
  for (std::size_t id = 0; id < channels_.size(); ++id) {
    Channel& c = channels_[id];
    if (c.index.empty()) continue;
    std::stable_sort(c.index.begin(), c.index.end(),
                     [](const auto& a, const auto& b) { return a.first < b.first; });
    scratch_.clear();
    PutU16(scratch_, static_cast<std::uint16_t>(id));
    PutU32(scratch_, static_cast<std::uint32_t>(c.index.size() * 16));
    for (const auto& [time, offset] : c.index) {
      PutU64(scratch_, time);
      PutU64(scratch_, offset);
    }
    index.message_index_offsets[static_cast<std::uint16_t>(id)] = offset_;
    std::string record;
    PutRecord(record, Opcode::kMessageIndex, scratch_);
    Emit(record);
    c.index.clear();
  }
  index.message_index_length = offset_ - indexes_start;
  chunk_indexes_.push_back(std::move(index));
  chunk_.clear();
  chunk_has_messages_ = false;
}

void Writer::Close() {
  if (closed_) return;
  closed_ = true;
  FlushChunk();
  for (Metadata& m : metadata_) {
    std::string content, record;
    PutString(content, m.name);
    PutStringMap(content, m.entries);
    PutRecord(record, Opcode::kMetadata, content);
    m.offset = offset_;
    m.length = record.size();
    Emit(record);
  }

  // Data end: the CRC of every byte before it, from the opening magic on.
  {
    std::string content, record;
    PutU32(content, crc_.Value());
    PutRecord(record, Opcode::kDataEnd, content);
    Emit(record);
  }
  crc_.Reset();  // from here: the summary's CRC

  struct Group {
    Opcode op;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  const std::uint64_t summary_start = offset_;
  const auto group = [&](Opcode op, const std::vector<std::string>& contents) {
    if (contents.empty()) return;
    const std::uint64_t start = offset_;
    std::string records;
    for (const auto& c : contents) PutRecord(records, op, c);
    Emit(records);
    groups.push_back({op, start, offset_ - start});
  };
  {
    std::vector<std::string> schemas, channels;
    for (std::size_t id = 1; id <= schemas_.size(); ++id) {
      schemas.push_back(SchemaContent(static_cast<std::uint16_t>(id)));
    }
    for (std::size_t id = 0; id < channels_.size(); ++id) {
      channels.push_back(ChannelContent(static_cast<std::uint16_t>(id)));
    }
    group(Opcode::kSchema, schemas);
    group(Opcode::kChannel, channels);
  }
  {
    std::string s;
    PutU64(s, message_count_);
    PutU16(s, static_cast<std::uint16_t>(schemas_.size()));
    PutU32(s, static_cast<std::uint32_t>(channels_.size()));
    PutU32(s, 0);  // attachments
    PutU32(s, static_cast<std::uint32_t>(metadata_.size()));
    PutU32(s, static_cast<std::uint32_t>(chunk_indexes_.size()));
    PutU64(s, first_time_);
    PutU64(s, last_time_);
    std::map<std::uint16_t, std::uint64_t> counts;
    for (std::size_t id = 0; id < channels_.size(); ++id) {
      counts[static_cast<std::uint16_t>(id)] = channels_[id].message_count;
    }
    PutU16U64Map(s, counts);
    group(Opcode::kStatistics, {s});
  }
  {
    std::vector<std::string> indexes;
    for (const ChunkIndex& c : chunk_indexes_) {
      std::string s;
      PutU64(s, c.start_time);
      PutU64(s, c.end_time);
      PutU64(s, c.offset);
      PutU64(s, c.length);
      PutU16U64Map(s, c.message_index_offsets);
      PutU64(s, c.message_index_length);
      PutString(s, CompressionName(options_.compression));
      PutU64(s, c.compressed_size);
      PutU64(s, c.uncompressed_size);
      indexes.push_back(std::move(s));
    }
    group(Opcode::kChunkIndex, indexes);
  }
  {
    std::vector<std::string> indexes;
    for (const Metadata& m : metadata_) {
      std::string s;
      PutU64(s, m.offset);
      PutU64(s, m.length);
      PutString(s, m.name);
      indexes.push_back(std::move(s));
    }
    group(Opcode::kMetadataIndex, indexes);
  }
  const std::uint64_t summary_offset_start = offset_;
  for (const Group& g : groups) {
    std::string content, record;
    PutU8(content, static_cast<std::uint8_t>(g.op));
    PutU64(content, g.start);
    PutU64(content, g.length);
    PutRecord(record, Opcode::kSummaryOffset, content);
    Emit(record);
  }
  // Footer: its CRC covers the summary and summary offset sections and the
  // footer's own fields before it.
  std::string footer;
  PutU8(footer, static_cast<std::uint8_t>(Opcode::kFooter));
  PutU64(footer, 8 + 8 + 4);
  PutU64(footer, summary_start);
  PutU64(footer, summary_offset_start);
  Emit(footer);
  std::string crc;
  PutU32(crc, crc_.Value());
  Emit(crc);
  Emit(kMagic);
  out_.flush();
}

}  // namespace linesim::mcap
