/* Stage 5's last step on the paths that write the display image from screen tiles (cl/fine_encode.cl,
 * cl/fine_subpixel.cl): a display pixel whose three subpixels belong to different tiles gets each colour
 * channel from its subpixel's tile, and its alpha here, once every tile is done, from the coverage byte
 * per subpixel the tiles left in straddle_cov. */
#include "common.h"

/* Alpha of the straddling display pixels (see the head of this file): the mean coverage of their three
 * subpixels, computed exactly as encode_pixel does from the views' alpha (0 or 1). 2D range: x = slot,
 * y = display row. */
kernel void encode_straddle_alpha(global const PmrEncodeParams* E, global const int* straddle_columns,
                                  uint straddle_slots, global const uchar* straddle_cov, global half* display) {
  const uint slot = get_global_id(0), i = get_global_id(1);
  if (slot >= straddle_slots || i >= (uint)E->display_h) return;
  global const uchar* c = straddle_cov + ((size_t)i * straddle_slots + slot) * 3;
  const ushort one = 0x3c00; /* 1.0 as a half */
  const ushort4 a = (ushort4)(0, 0, 0, c[0] ? one : 0), b = (ushort4)(0, 0, 0, c[1] ? one : 0);
  const ushort4 d = (ushort4)(0, 0, 0, c[2] ? one : 0);
  const size_t pixel = (size_t)i * (size_t)E->display_w + (size_t)straddle_columns[slot];
  ((global ushort*)display)[pixel * 4 + 3] = encode_pixel(a, b, d).w;
}
