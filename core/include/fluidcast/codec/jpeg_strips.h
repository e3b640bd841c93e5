// One frame's JPEG encoded as horizontal strips on several threads: each strip is a baseline JPEG
// of its own (the same tables, its DC prediction starting afresh), and the strips' scans joined
// with restart markers between them are the scan of the whole frame — which decodes to the very
// pixels a single encode gives, while the strips encode at once (bench/results/encode-strips-*).
#pragma once

#include <cstdint>
#include <vector>

namespace fluidcast::codec {

// Strips start on a multiple of this many rows: a row of 4:2:0 blocks (16 × 16 pixels), and so a
// row of blocks at every subsampling.
inline constexpr int kJpegStripRowMultiple = 16;

// Rows per strip to cut `height` rows into at most `strips` strips, a multiple of
// kJpegStripRowMultiple (the last strip takes what is left).
int jpeg_strip_rows(int height, int strips);

// The strips of one image, top to bottom, each `strip_rows` rows but the last (at most that),
// encoded alone with the same options, as one JPEG of the whole image. Throws
// std::invalid_argument for strips that do not fit together (different widths or tables, a strip
// not a whole number of blocks high, more blocks in a strip than a restart interval counts,
// TurboJPEG's environment asking for optimized, progressive or restart-marked output, or data
// that is not a baseline JPEG).
std::vector<std::uint8_t> join_jpeg_strips(const std::vector<std::vector<std::uint8_t>>& strips,
                                           int strip_rows);

}  // namespace fluidcast::codec
