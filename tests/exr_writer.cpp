// glint tests — EXR files written with OpenEXR's C++ library. See exr_writer.h.
#include "exr_writer.h"

#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <half.h>

#include <cstdint>
#include <cstdio>
#include <exception>
#include <vector>

static_assert((int)EXR_COMPRESSION_NONE == (int)Imf::NO_COMPRESSION &&
                  (int)EXR_COMPRESSION_PIZ == (int)Imf::PIZ_COMPRESSION &&
                  (int)EXR_COMPRESSION_DWAB == (int)Imf::DWAB_COMPRESSION,
              "the C core's compression numbers are the C++ library's");
static_assert((int)EXR_PIXEL_UINT == (int)Imf::UINT && (int)EXR_PIXEL_HALF == (int)Imf::HALF &&
                  (int)EXR_PIXEL_FLOAT == (int)Imf::FLOAT,
              "the C core's pixel types are the C++ library's");

extern "C" int write_test_exr(const char *path, exr_storage_t storage, exr_compression_t comp, const test_chan *chans,
                              int nchan, exr_attr_box2i_t dw, exr_attr_box2i_t disp, test_value_fn value) {
    try {
        Imath::Box2i data(Imath::V2i(dw.min.x, dw.min.y), Imath::V2i(dw.max.x, dw.max.y));
        Imath::Box2i display(Imath::V2i(disp.min.x, disp.min.y), Imath::V2i(disp.max.x, disp.max.y));
        Imf::Header header(display, data, 1.0f, Imath::V2f(0.0f, 0.0f), 1.0f, Imf::INCREASING_Y,
                           static_cast<Imf::Compression>(comp));
        int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
        // One buffer a channel, of its samples only, in the channel's own type (the library does not
        // convert on writing in every codec).
        std::vector<std::vector<float>> floats((size_t)nchan);
        std::vector<std::vector<half>> halves((size_t)nchan);
        std::vector<std::vector<uint32_t>> uints((size_t)nchan);
        Imf::FrameBuffer fb;
        for (int c = 0; c < nchan; c++) {
            int s = chans[c].sampling ? chans[c].sampling : 1, sw = w / s, sh = h / s;
            auto type = static_cast<Imf::PixelType>(chans[c].type);
            header.channels().insert(chans[c].name, Imf::Channel(type, s, s));
            floats[(size_t)c].resize((size_t)sw * (size_t)sh);
            halves[(size_t)c].resize((size_t)sw * (size_t)sh);
            uints[(size_t)c].resize((size_t)sw * (size_t)sh);
            for (int j = 0; j < sh; j++)
                for (int i = 0; i < sw; i++) {
                    float v = value(c, dw.min.x + i * s, dw.min.y + j * s);
                    floats[(size_t)c][(size_t)(j * sw + i)] = v;
                    halves[(size_t)c][(size_t)(j * sw + i)] = half(v);
                    uints[(size_t)c][(size_t)(j * sw + i)] = (uint32_t)v;
                }
            void *base = type == Imf::UINT   ? (void *)uints[(size_t)c].data()
                         : type == Imf::HALF ? (void *)halves[(size_t)c].data()
                                             : (void *)floats[(size_t)c].data();
            fb.insert(chans[c].name,
                      Imf::Slice::Make(type, base, data.min, (int64_t)w, (int64_t)h, (size_t)0, (size_t)0, s, s));
        }
        if (storage == EXR_STORAGE_TILED) {
            header.setTileDescription(Imf::TileDescription(16, 8, Imf::ONE_LEVEL));
            Imf::TiledOutputFile out(path, header, 0);
            out.setFrameBuffer(fb);
            out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
        } else {
            Imf::OutputFile out(path, header, 0);
            out.setFrameBuffer(fb);
            out.writePixels(h);
        }
        return 0;
    } catch (const std::exception &e) {
        std::fprintf(stderr, "write_test_exr(%s): %s\n", path, e.what());
        return -1;
    }
}
