#include "eval/video.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/dict.h>
#include <libavutil/error.h>
#include <libavutil/log.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>

#include "core/error.h"

namespace cradle::eval {
namespace {

// Container and encoder chosen by an extension.
struct Format {
  const char* muxer;    // libavformat short name
  const char* encoder;  // libavcodec encoder name
  bool x264;            // takes libx264's private options
};

// The format for a file's extension, or nullptr when it is not supported.
const Format* format_for(const std::filesystem::path& file) {
  static constexpr Format kMp4{"mp4", "libx264", true};
  static constexpr Format kAvi{"avi", "mpeg4", false};
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".mp4") return &kMp4;
  if (ext == ".avi") return &kAvi;
  return nullptr;
}

// FFmpeg's text for an error code.
std::string av_text(int code) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(code, text, sizeof text);
  return text;
}

// Owners of FFmpeg objects.
struct MuxFree {
  void operator()(AVFormatContext* f) const {
    if (f->pb) avio_closep(&f->pb);
    avformat_free_context(f);
  }
};
struct CodecFree {
  void operator()(AVCodecContext* c) const { avcodec_free_context(&c); }
};
struct SwsFree {
  void operator()(SwsContext* s) const { sws_freeContext(s); }
};
struct FrameFree {
  void operator()(AVFrame* f) const { av_frame_free(&f); }
};
struct PacketFree {
  void operator()(AVPacket* p) const { av_packet_free(&p); }
};

}  // namespace

struct VideoWriter::Impl {
  std::filesystem::path file;
  int width = 0, height = 0;  // frame size given by the caller
  std::unique_ptr<AVFormatContext, MuxFree> mux;
  std::unique_ptr<AVCodecContext, CodecFree> codec;
  std::unique_ptr<SwsContext, SwsFree> sws;
  std::unique_ptr<AVFrame, FrameFree> frame;  // reused for every picture
  std::unique_ptr<AVPacket, PacketFree> packet;
  AVStream* stream = nullptr;
  int frames = 0;
  bool open = false;  // header written, trailer not yet

  Impl(const std::filesystem::path& path, int w, int h, double fps);
  ~Impl() {
    if (!open) return;
    try {
      finish();
    } catch (...) {
      // A destructor cannot report; close() is the call that does.
    }
  }

  // Throws std::runtime_error naming the file, the step and FFmpeg's reason.
  [[noreturn]] void fail(const char* step, int code) const {
    throw std::runtime_error("video file '" + file.string() + "': " + step +
                             " failed: " + av_text(code));
  }

  void setup(const Format& format, double fps);
  void encode(const AVFrame* picture);
  void finish();
};

VideoWriter::Impl::Impl(const std::filesystem::path& path, int w, int h, double fps)
    : file(path), width(w), height(h) {
  const Format* format = format_for(file);
  if (!format) {
    throw UserError("video file '" + file.string() + "': unsupported extension '" +
                    file.extension().string() + "' (expected .mp4 or .avi)");
  }
  if (width <= 0 || height <= 0) {
    throw UserError("video file '" + file.string() + "': frame size " + std::to_string(width) +
                    "x" + std::to_string(height) + " must be positive");
  }
  if (!std::isfinite(fps) || fps <= 0) {
    throw UserError("video file '" + file.string() + "': frame rate " + std::to_string(fps) +
                    " must be positive");
  }
  av_log_set_level(AV_LOG_ERROR);
  // A failed setup leaves no half-made file behind.
  try {
    setup(*format, fps);
  } catch (...) {
    const bool created = mux && mux->pb;
    packet.reset();
    frame.reset();
    sws.reset();
    codec.reset();
    mux.reset();
    if (created) {
      std::error_code ignored;
      std::filesystem::remove(file, ignored);
    }
    throw;
  }
}

void VideoWriter::Impl::setup(const Format& format, double fps) {
  // The "file:" prefix keeps FFmpeg from reading a colon in the path as a protocol name.
  const std::string url = "file:" + file.string();
  const int padded_w = width + width % 2, padded_h = height + height % 2;
  const AVRational rate = av_d2q(fps, 65535);

  // Muxer.
  AVFormatContext* raw_mux = nullptr;
  int rc = avformat_alloc_output_context2(&raw_mux, nullptr, format.muxer, url.c_str());
  if (rc < 0) fail("creating the muxer", rc);
  mux.reset(raw_mux);

  // Encoder.
  const AVCodec* encoder = avcodec_find_encoder_by_name(format.encoder);
  if (!encoder) {
    throw std::runtime_error("video file '" + file.string() + "': FFmpeg has no " + format.encoder +
                             " encoder");
  }
  codec.reset(avcodec_alloc_context3(encoder));
  if (!codec) fail("allocating the encoder", AVERROR(ENOMEM));
  AVCodecContext* c = codec.get();
  c->width = padded_w;
  c->height = padded_h;
  c->pix_fmt = AV_PIX_FMT_YUV420P;
  c->framerate = rate;
  c->time_base = av_inv_q(rate);
  c->sample_aspect_ratio = AVRational{1, 1};
  c->color_range = AVCOL_RANGE_MPEG;
  c->colorspace = AVCOL_SPC_SMPTE170M;
  c->color_primaries = AVCOL_PRI_SMPTE170M;
  c->color_trc = AVCOL_TRC_SMPTE170M;
  // A few threads: enough for real time, a bounded number of frames in flight.
  c->thread_count = static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 4u));
  if (mux->oformat->flags & AVFMT_GLOBALHEADER) c->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  if (format.x264) {
    av_opt_set(c->priv_data, "preset", "veryfast", 0);
    av_opt_set(c->priv_data, "crf", "23", 0);
  } else {
    c->flags |= AV_CODEC_FLAG_QSCALE;
    c->global_quality = FF_QP2LAMBDA * 3;
  }
  rc = avcodec_open2(c, encoder, nullptr);
  if (rc < 0) fail("opening the encoder", rc);

  // Stream.
  stream = avformat_new_stream(mux.get(), nullptr);
  if (!stream) fail("adding the stream", AVERROR(ENOMEM));
  rc = avcodec_parameters_from_context(stream->codecpar, c);
  if (rc < 0) fail("describing the stream", rc);
  stream->time_base = c->time_base;
  stream->avg_frame_rate = rate;
  stream->r_frame_rate = rate;

  // Picture buffer, converter and packet, made once.
  frame.reset(av_frame_alloc());
  packet.reset(av_packet_alloc());
  if (!frame || !packet) fail("allocating buffers", AVERROR(ENOMEM));
  frame->format = c->pix_fmt;
  frame->width = padded_w;
  frame->height = padded_h;
  frame->color_range = c->color_range;
  frame->colorspace = c->colorspace;
  frame->color_primaries = c->color_primaries;
  frame->color_trc = c->color_trc;
  rc = av_frame_get_buffer(frame.get(), 0);
  if (rc < 0) fail("allocating the picture", rc);
  sws.reset(sws_getContext(width, height, AV_PIX_FMT_RGB24, width, height, AV_PIX_FMT_YUV420P,
                           SWS_BILINEAR, nullptr, nullptr, nullptr));
  if (!sws) fail("creating the colour converter", AVERROR(EINVAL));

  // File and header; a file that cannot be created is the user's to fix.
  rc = avio_open(&mux->pb, url.c_str(), AVIO_FLAG_WRITE);
  if (rc < 0) {
    throw UserError("video file '" + file.string() + "': cannot open for writing: " + av_text(rc));
  }
  AVDictionary* options = nullptr;
  if (format.x264) av_dict_set(&options, "movflags", "+faststart", 0);
  rc = avformat_write_header(mux.get(), &options);
  av_dict_free(&options);
  if (rc < 0) fail("writing the header", rc);
  open = true;
}

void VideoWriter::Impl::encode(const AVFrame* picture) {
  int rc = avcodec_send_frame(codec.get(), picture);
  if (rc < 0) fail("encoding", rc);
  // Every packet the encoder has ready goes straight to the file.
  for (;;) {
    rc = avcodec_receive_packet(codec.get(), packet.get());
    if (rc == AVERROR(EAGAIN) || rc == AVERROR_EOF) return;
    if (rc < 0) fail("encoding", rc);
    av_packet_rescale_ts(packet.get(), codec->time_base, stream->time_base);
    packet->stream_index = stream->index;
    rc = av_interleaved_write_frame(mux.get(), packet.get());  // takes the packet's data
    if (rc < 0) fail("writing", rc);
  }
}

void VideoWriter::Impl::finish() {
  open = false;
  encode(nullptr);
  int rc = av_write_trailer(mux.get());
  if (rc < 0) fail("writing the trailer", rc);
  rc = avio_closep(&mux->pb);
  if (rc < 0) fail("closing", rc);
}

VideoWriter::VideoWriter(const std::filesystem::path& file, int width, int height, double fps)
    : impl_(std::make_unique<Impl>(file, width, height, fps)) {}

VideoWriter::VideoWriter(VideoWriter&&) noexcept = default;
VideoWriter& VideoWriter::operator=(VideoWriter&&) noexcept = default;
VideoWriter::~VideoWriter() = default;

void VideoWriter::write(std::span<const std::uint8_t> rgb) {
  if (!impl_ || !impl_->open) throw std::logic_error("VideoWriter::write after close");
  Impl& m = *impl_;
  const std::size_t expected = static_cast<std::size_t>(m.width) * m.height * 3;
  if (rgb.size() != expected) {
    throw std::invalid_argument("VideoWriter::write: got " + std::to_string(rgb.size()) +
                                " bytes, expected " + std::to_string(expected) + " (" +
                                std::to_string(m.width) + "x" + std::to_string(m.height) + " RGB)");
  }
  AVFrame* f = m.frame.get();
  // The encoder may still hold the last picture; FFmpeg then gives the frame a fresh buffer.
  int rc = av_frame_make_writable(f);
  if (rc < 0) m.fail("preparing the picture", rc);

  // RGB to yuv420p, then the padding column / row (if any) repeats the last one.
  const std::uint8_t* src[1] = {rgb.data()};
  const int src_stride[1] = {m.width * 3};
  sws_scale(m.sws.get(), src, src_stride, 0, m.height, f->data, f->linesize);
  if (f->width != m.width) {
    for (int y = 0; y < m.height; ++y) {
      std::uint8_t* row = f->data[0] + static_cast<std::ptrdiff_t>(y) * f->linesize[0];
      row[m.width] = row[m.width - 1];
    }
  }
  if (f->height != m.height) {
    std::memcpy(f->data[0] + static_cast<std::ptrdiff_t>(m.height) * f->linesize[0],
                f->data[0] + static_cast<std::ptrdiff_t>(m.height - 1) * f->linesize[0], f->width);
  }

  f->pts = m.frames;
  f->quality = m.codec->global_quality;
  m.encode(f);
  ++m.frames;
}

void VideoWriter::close() {
  if (impl_ && impl_->open) impl_->finish();
}

int VideoWriter::frames() const { return impl_ ? impl_->frames : 0; }

}  // namespace cradle::eval
