// Streamed video files for evaluation: RGB frames go to the encoder as they come, so memory stays
// bounded by the encoder's own delay however long the episode. Built on the FFmpeg libraries.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>

namespace cradle::eval {

// Writes RGB frames to a video file. The extension picks the format (case-insensitive):
//   .mp4  H.264 (libx264, yuv420p, CRF 23, preset veryfast) in MP4, index at the front (faststart);
//   .avi  MPEG-4 part 2 (yuv420p, fixed quantiser 3) in AVI.
// Colours are converted with BT.601 limited range and tagged so. An odd width or height is padded
// to even (yuv420p needs it) by repeating the last column / row, so the file is one pixel larger.
// FFmpeg's log level (a process-wide setting of FFmpeg) is set to errors only on construction.
class VideoWriter {
 public:
  // Opens `file` for frames of width x height at `fps` frames per second (any positive rate;
  // it is stored as a fraction with denominator <= 65535). Throws cradle::UserError for an
  // unsupported extension, a non-positive size or rate, or a file that cannot be created.
  VideoWriter(const std::filesystem::path& file, int width, int height, double fps);
  VideoWriter(VideoWriter&&) noexcept;
  VideoWriter& operator=(VideoWriter&&) noexcept;  // finishes the file it replaces
  ~VideoWriter();                                  // finishes the file if close() was not called

  // Appends one frame: width*height*3 bytes of RGB, row 0 at the top. Throws std::invalid_argument
  // on a wrong size, std::logic_error after close(), std::runtime_error if FFmpeg fails.
  void write(std::span<const std::uint8_t> rgb);

  // Flushes the encoder, writes the trailer and closes the file. Later calls do nothing.
  void close();

  // Frames written so far.
  int frames() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cradle::eval
