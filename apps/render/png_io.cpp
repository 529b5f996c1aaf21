// PNG files through libpng (png_io.h).
#include "apps/render/png_io.h"

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <ostream>

#include <sffd/error.h>

#include "io/atomic_file.h"

namespace sffd::gl {

// ---------------------------------------------------------------------------------------------
// PNG through libpng. Its errors longjmp: the calls live in functions with trivially destructible
// locals only, and report failure through a message buffer.
// ---------------------------------------------------------------------------------------------

namespace {

struct PngError {
  char message[256] = {0};
};

void pngError(png_structp png, png_const_charp msg) {
  auto* e = static_cast<PngError*>(png_get_error_ptr(png));
  std::snprintf(e->message, sizeof e->message, "%s", msg ? msg : "libpng error");
  png_longjmp(png, 1);
}
void pngWarning(png_structp, png_const_charp) {}

void pngWriteToStream(png_structp png, png_bytep data, png_size_t length) {
  static_cast<std::ostream*>(png_get_io_ptr(png))->write(reinterpret_cast<const char*>(data),
                                                          static_cast<std::streamsize>(length));
}
void pngFlushStream(png_structp png) { static_cast<std::ostream*>(png_get_io_ptr(png))->flush(); }

// rows: `height` pointers to RGB rows. Returns false with e.message set on failure.
bool writePngRows(std::ostream* out, int width, int height, png_bytep* rows, PngError* e) {
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, e, pngError, pngWarning);
  if (!png) {
    std::snprintf(e->message, sizeof e->message, "libpng: cannot create a writer");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    if (!e->message[0]) std::snprintf(e->message, sizeof e->message, "libpng: cannot create an info struct");
    png_destroy_write_struct(&png, info ? &info : nullptr);
    return false;
  }
  png_set_write_fn(png, out, pngWriteToStream, pngFlushStream);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, PNG_COLOR_TYPE_RGB,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 6);
  png_write_info(png, info);
  png_write_image(png, rows);
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return true;
}

struct PngReadResult {
  png_uint_32 width = 0, height = 0;
};

// Reads the header into r, then calls back for the pixel buffer (RGBA, 8 bits) through `rows`.
bool readPngFile(FILE* f, PngReadResult* r, std::vector<uint8_t>* pixels, std::vector<png_bytep>* rows, PngError* e) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, e, pngError, pngWarning);
  if (!png) {
    std::snprintf(e->message, sizeof e->message, "libpng: cannot create a reader");
    return false;
  }
  png_infop info = png_create_info_struct(png);
  if (!info || setjmp(png_jmpbuf(png))) {
    if (!e->message[0]) std::snprintf(e->message, sizeof e->message, "libpng: cannot create an info struct");
    png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
    return false;
  }
  png_init_io(png, f);
  png_set_user_limits(png, 1u << 15, 1u << 15);
  png_read_info(png, info);
  png_set_expand(png);
  png_set_strip_16(png);
  png_set_gray_to_rgb(png);
  png_set_add_alpha(png, 0xff, PNG_FILLER_AFTER);
  png_set_interlace_handling(png);
  png_read_update_info(png, info);
  r->width = png_get_image_width(png, info);
  r->height = png_get_image_height(png, info);
  if (png_get_rowbytes(png, info) != static_cast<size_t>(r->width) * 4) {
    std::snprintf(e->message, sizeof e->message, "unexpected PNG row layout");
    png_destroy_read_struct(&png, &info, nullptr);
    return false;
  }
  // Resizing may throw bad_alloc: no libpng frame is between here and the caller.
  pixels->resize(static_cast<size_t>(r->width) * r->height * 4);
  rows->resize(r->height);
  for (png_uint_32 y = 0; y < r->height; ++y) (*rows)[y] = pixels->data() + static_cast<size_t>(y) * r->width * 4;
  png_read_image(png, rows->data());
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return true;
}

}  // namespace

void writePng(const std::string& path, const RgbaImage& image) {
  if (image.width < 1 || image.height < 1 ||
      image.rgba.size() != static_cast<size_t>(image.width) * image.height * 4)
    throw Error(ErrorKind::Internal, "writePng: the image has no pixels or the wrong size");
  std::vector<uint8_t> rgb(static_cast<size_t>(image.width) * image.height * 3);
  for (size_t i = 0, n = static_cast<size_t>(image.width) * image.height; i < n; ++i)
    std::memcpy(&rgb[i * 3], &image.rgba[i * 4], 3);
  std::vector<png_bytep> rows(static_cast<size_t>(image.height));
  for (int y = 0; y < image.height; ++y) rows[static_cast<size_t>(y)] = &rgb[static_cast<size_t>(y) * image.width * 3];
  writeFileAtomically(
      path,
      [&](std::ostream& out) {
        PngError e;
        if (!writePngRows(&out, image.width, image.height, rows.data(), &e))
          throw Error(ErrorKind::Internal, path + ": cannot encode the PNG (" + e.message + ")");
      },
      /*binary=*/true);
}

RgbaImage readPng(const std::string& path) {
  FILE* f = std::fopen(path.c_str(), "rb");
  if (!f) throw inputError(path, 0, std::string("cannot open: ") + std::strerror(errno));
  PngReadResult r;
  PngError e;
  RgbaImage img;
  std::vector<png_bytep> rows;
  bool ok = readPngFile(f, &r, &img.rgba, &rows, &e);
  std::fclose(f);
  if (!ok) throw inputError(path, 0, std::string("not a readable PNG (") + e.message + ")");
  img.width = static_cast<int>(r.width);
  img.height = static_cast<int>(r.height);
  return img;
}

}  // namespace sffd::gl
