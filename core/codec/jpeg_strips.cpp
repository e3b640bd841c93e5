#include "fluidcast/codec/jpeg_strips.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace fluidcast::codec {
namespace {

constexpr std::uint8_t kMarker = 0xFF;
constexpr int kMostJpegRows = 65500;  // libjpeg's JPEG_MAX_DIMENSION: decoders refuse more
constexpr std::uint8_t kSoi = 0xD8, kEoi = 0xD9, kSos = 0xDA, kDri = 0xDD, kSof0 = 0xC0,
                       kRst0 = 0xD0;

[[noreturn]] void refuse(const std::string& why) {
  throw std::invalid_argument("jpeg strips: " + why);
}

int read16(const std::vector<std::uint8_t>& jpeg, std::size_t at) {
  return jpeg[at] << 8 | jpeg[at + 1];
}

// Where a strip's parts are: its header (SOI up to, not including, SOS), the SOS segment, and the
// entropy-coded data between SOS and EOI; with the frame's size and block size from its SOF.
struct Parts {
  std::size_t sof = 0;  // the SOF0 segment's marker
  std::size_t sos = 0;  // the SOS segment's marker
  std::size_t data = 0;
  std::size_t end = 0;  // the EOI marker
  int width = 0, height = 0, block_width = 8, block_height = 8;
};

Parts parts_of(const std::vector<std::uint8_t>& jpeg) {
  if (jpeg.size() < 4 || jpeg[0] != kMarker || jpeg[1] != kSoi ||
      jpeg[jpeg.size() - 2] != kMarker || jpeg[jpeg.size() - 1] != kEoi) {
    refuse("a strip is not a whole JPEG");
  }
  Parts parts;
  std::size_t at = 2;
  while (parts.sos == 0) {
    if (at + 4 > jpeg.size() || jpeg[at] != kMarker) refuse("a strip's header is damaged");
    const std::uint8_t marker = jpeg[at + 1];
    const std::size_t length = static_cast<std::size_t>(read16(jpeg, at + 2));
    if (at + 2 + length > jpeg.size()) refuse("a strip's header is damaged");
    if (marker == kDri) refuse("a strip already has restart markers");
    if (marker >= 0xC1 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC) {
      refuse("a strip is not a baseline JPEG");
    }
    if (marker == kSof0) {
      if (length < 8 || length < 8 + 3 * static_cast<std::size_t>(jpeg[at + 9])) {
        refuse("a strip's frame header is damaged");
      }
      parts.sof = at;
      parts.height = read16(jpeg, at + 5);
      parts.width = read16(jpeg, at + 7);
      const int components = jpeg[at + 9];
      int most_h = 1, most_v = 1;
      for (int c = 0; c < components; ++c) {
        const std::uint8_t factors = jpeg[at + 11 + 3 * c];
        most_h = std::max(most_h, factors >> 4);
        most_v = std::max(most_v, factors & 0x0F);
      }
      parts.block_width = 8 * most_h;
      parts.block_height = 8 * most_v;
    }
    if (marker == kSos) {
      parts.sos = at;
      parts.data = at + 2 + length;
    }
    at += 2 + length;
  }
  if (parts.sof == 0) refuse("a strip has no baseline frame header");
  parts.end = jpeg.size() - 2;
  return parts;
}

}  // namespace

int jpeg_strip_rows(int height, int strips) {
  const int m = kJpegStripRowMultiple;
  const int rows = (height + std::max(strips, 1) - 1) / std::max(strips, 1);
  return std::max(m, (rows + m - 1) / m * m);
}

std::vector<std::uint8_t> join_jpeg_strips(const std::vector<std::vector<std::uint8_t>>& strips,
                                           int strip_rows) {
  if (strips.empty()) refuse("no strips");
  if (strips.size() == 1) return strips.front();
  const std::vector<std::uint8_t>& first = strips.front();
  const Parts head = parts_of(first);
  if (strip_rows != head.height || strip_rows % head.block_height != 0) {
    refuse("the first strip is " + std::to_string(head.height) + " rows, not " +
           std::to_string(strip_rows) + ", a whole number of blocks");
  }
  const int blocks_across = (head.width + head.block_width - 1) / head.block_width;
  const int interval = blocks_across * (strip_rows / head.block_height);
  if (interval > 0xFFFF) refuse("a strip holds more blocks than a restart interval can count");

  std::vector<Parts> all;
  int height = 0;
  for (std::size_t k = 0; k < strips.size(); ++k) {
    all.push_back(k == 0 ? head : parts_of(strips[k]));
    const Parts& p = all.back();
    if (p.width != head.width || p.block_width != head.block_width ||
        p.block_height != head.block_height) {
      refuse("strip " + std::to_string(k) + " is not as wide or not blocked as the first");
    }
    if (k + 1 < strips.size() ? p.height != strip_rows : p.height > strip_rows) {
      refuse("strip " + std::to_string(k) + " is " + std::to_string(p.height) + " rows, not " +
             std::to_string(strip_rows));
    }
    // The same tables: every strip's header matches the first's, but for the height in its SOF.
    const std::vector<std::uint8_t>& s = strips[k];
    bool same = p.data == head.data && p.sof == head.sof;
    for (std::size_t at = 0; same && at < head.data; ++at) {
      same = at == head.sof + 5 || at == head.sof + 6 || s[at] == first[at];
    }
    if (!same) refuse("strip " + std::to_string(k) + " was not encoded as the first was");
    height += p.height;
  }
  if (height > kMostJpegRows) refuse("the strips are more rows than a JPEG holds");

  std::vector<std::uint8_t> jpeg(first.begin(),
                                 first.begin() + static_cast<std::ptrdiff_t>(head.sos));
  jpeg[head.sof + 5] = static_cast<std::uint8_t>(height >> 8);
  jpeg[head.sof + 6] = static_cast<std::uint8_t>(height & 0xFF);
  const std::uint8_t restart_interval[] = {kMarker,
                                           kDri,
                                           0,
                                           4,
                                           static_cast<std::uint8_t>(interval >> 8),
                                           static_cast<std::uint8_t>(interval & 0xFF)};
  jpeg.insert(jpeg.end(), std::begin(restart_interval), std::end(restart_interval));
  jpeg.insert(jpeg.end(), first.begin() + static_cast<std::ptrdiff_t>(head.sos),
              first.begin() + static_cast<std::ptrdiff_t>(head.data));
  for (std::size_t k = 0; k < strips.size(); ++k) {
    const std::vector<std::uint8_t>& s = strips[k];
    jpeg.insert(jpeg.end(), s.begin() + static_cast<std::ptrdiff_t>(all[k].data),
                s.begin() + static_cast<std::ptrdiff_t>(all[k].end));
    if (k + 1 < strips.size()) {
      jpeg.push_back(kMarker);
      jpeg.push_back(static_cast<std::uint8_t>(kRst0 + k % 8));
    }
  }
  jpeg.push_back(kMarker);
  jpeg.push_back(kEoi);
  return jpeg;
}

}  // namespace fluidcast::codec
