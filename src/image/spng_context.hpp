// Image files, internal: the owner of a libspng context, shared by the PNG writer and reader
// (image_io.cpp) and the texture decoders (image_decode.cpp).
#pragma once

#include <spng.h>

#include <new>

namespace covrast {

/// Owns a libspng context.
class SpngContext {
 public:
  explicit SpngContext(int flags) : ctx_(spng_ctx_new(flags)) {
    if (ctx_ == nullptr) throw std::bad_alloc();
  }
  ~SpngContext() { spng_ctx_free(ctx_); }
  SpngContext(const SpngContext&) = delete;
  SpngContext& operator=(const SpngContext&) = delete;
  spng_ctx* get() const { return ctx_; }

 private:
  spng_ctx* ctx_;
};

}  // namespace covrast
