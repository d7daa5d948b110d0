/* A planted library for tests/portable/test_portable_library.py: it defines functions with the
 * names of the dependencies' own (OpenEXR Core, Embree, libpng, zlib, cJSON, Assimp, OpenColorIO,
 * yaml-cpp, expat) that print which one was called and abort(). Loaded first with RTLD_GLOBAL, it
 * stands for a host whose libraries have other versions of those symbols: a libdwivedi whose
 * references to them go through the dynamic linker ends in one of these and dies (the normal
 * build does: the test checks it, so that the harness is shown to catch interposition); the
 * portable library, which binds them inside itself, never reaches them. */
#include <stdio.h>
#include <stdlib.h>

#define PLANT(c_name, symbol)                                                                  \
    void c_name(void) __asm__(symbol);                                                         \
    __attribute__((visibility("default"))) void c_name(void) {                                  \
        fprintf(stderr, "planted_symbols: %s was called: a dependency symbol was interposed\n", \
                symbol);                                                                       \
        fflush(stderr);                                                                        \
        abort();                                                                               \
    }

/* OpenEXR Core (src/output/exr.c) */
PLANT(p_exr_start_write, "exr_start_write")
PLANT(p_exr_add_part, "exr_add_part")
PLANT(p_exr_write_header, "exr_write_header")
PLANT(p_exr_get_default_error_message, "exr_get_default_error_message")
/* Embree 3 and 4 share these names (src/geom/embree.c) */
PLANT(p_rtcNewDevice, "rtcNewDevice")
PLANT(p_rtcNewScene, "rtcNewScene")
PLANT(p_rtcCommitScene, "rtcCommitScene")
PLANT(p_rtcIntersect1, "rtcIntersect1")
PLANT(p_rtcPointQuery, "rtcPointQuery")
/* libpng (src/output/png.c) */
PLANT(p_png_create_write_struct, "png_create_write_struct")
PLANT(p_png_create_info_struct, "png_create_info_struct")
PLANT(p_png_write_row, "png_write_row")
/* zlib (OpenEXR's and libpng's compression) */
PLANT(p_deflate, "deflate")
PLANT(p_deflateInit_, "deflateInit_")
PLANT(p_deflateInit2_, "deflateInit2_")
PLANT(p_compress2, "compress2")
PLANT(p_compressBound, "compressBound")
PLANT(p_crc32, "crc32")
/* cJSON and Assimp (src/scenefile) */
PLANT(p_cJSON_ParseWithLengthOpts, "cJSON_ParseWithLengthOpts")
PLANT(p_cJSON_Delete, "cJSON_Delete")
PLANT(p_aiImportFileExWithProperties, "aiImportFileExWithProperties")
PLANT(p_aiReleaseImport, "aiReleaseImport")
/* OpenColorIO 2.1 (src/output/display.cpp) and yaml-cpp, expat inside it */
PLANT(p_ocio_create_from_stream, "_ZN16OpenColorIO_v2_16Config16CreateFromStreamERSi")
PLANT(p_ocio_cpu_processor, "_ZNK16OpenColorIO_v2_19Processor22getDefaultCPUProcessorEv")
PLANT(p_ocio_packed_image_desc, "_ZN16OpenColorIO_v2_115PackedImageDescC1EPvlll")
PLANT(p_yaml_load, "_ZN4YAML4LoadERSi")
PLANT(p_yaml_node_data, "_ZN4YAML6detail9node_data8set_typeENS_8NodeType5valueE")
PLANT(p_XML_ParserCreate, "XML_ParserCreate")
