/* Stage 5's last step on the paths that write the display image from screen tiles (cl/fine_encode.cl,
 * cl/fine_subpixel.cl): a display pixel whose three subpixels belong to different tiles gets each colour
 * channel and each subpixel's own alpha from its subpixel's tile, and its alpha here, once every tile is
 * done, from those three subpixel alphas. */
#include "common.h"

/* Alpha of the straddling display pixels (see the head of this file): the mean of their three subpixels'
 * alpha, computed exactly as encode_pixel does. 2D range: x = slot (the straddling columns), y = display
 * row. */
kernel void encode_straddle_alpha(global const PmrEncodeParams* E, global const int* straddle_columns,
                                  uint straddle_slots, global const ushort* sub_alpha, global half* display) {
  const uint slot = get_global_id(0), i = get_global_id(1);
  if (slot >= straddle_slots || i >= (uint)E->display_h) return;
  const size_t pixel = (size_t)i * (size_t)E->display_w + (size_t)straddle_columns[slot];
  const ushort3 a = vload3(pixel, sub_alpha);
  const ushort4 s0 = (ushort4)(0, 0, 0, a.x), s1 = (ushort4)(0, 0, 0, a.y), s2 = (ushort4)(0, 0, 0, a.z);
  ((global ushort*)display)[pixel * 4 + 3] = encode_pixel(s0, s1, s2).w;
}
