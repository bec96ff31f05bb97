/* Session 19, H200 call 5: the probe TRIANGLE_QUADS (not kept), as it stood in kernels/stages/triangles.cl
 * before the kept loop of two triangles a work-item (a build option: -DTRIANGLE_QUADS=1). */
#ifdef TRIANGLE_QUADS  /* probe: four triangles a work-item, two cells' as three 16-byte stores */
    for (uint r0 = 4 * (uint)get_local_id(0); r0 < stop; r0 += 4 * group) {
        uint r = r0, until = min(r0 + 4, stop);
        while (r < until) {
            if (r >= patch_end) {
                ulong at = start + r;
                p = patch_end ? patch_after(index_offsets, p, last, 3 * at) : patch_of(index_offsets, p, last, 3 * at);
                patch_start = (uint)(index_offsets[p] / 3) - (uint)start;
                patch_end = (uint)min(index_offsets[p + 1] / 3 - start, (ulong)stop);
                f = patch_factors(factors[p], &collapsed);
                base = (uint)vertex_offsets[p];
#ifdef PATTERN_TRIANGLE_AT
                direct = pattern_triangles_of(f, collapsed, &grid);
#endif
            }
            uint t = r - patch_start;
#ifdef PATTERN_TRIANGLE_AT
            if (direct) {
                int pairs;
                uint d;
                uint3 triangle = pattern_triangle_pair(&grid, t, &pairs, &d) + base;
                d += base;
                int both = pairs && r + 1 < until;
                __global uint *to = out + 3 * r;
                if (both && r + 3 < until && r + 3 < patch_end && ((ulong)to & 15) == 0) {
                    int pairs2;
                    uint d2;
                    uint3 next = pattern_triangle_pair(&grid, t + 2, &pairs2, &d2) + base;
                    if (pairs2) {
                        __global uint4 *to4 = (__global uint4 *)to;
                        to4[0] = (uint4)(triangle.x, triangle.y, triangle.z, triangle.x);
                        to4[1] = (uint4)(triangle.z, d, next.x, next.y);
                        to4[2] = (uint4)(next.z, next.x, next.z, d2 + base);
                        r += 4;
                        continue;
                    }
                }
                if (both && ((ulong)to & 7) == 0) {
                    __global uint2 *to2 = (__global uint2 *)to;
                    to2[0] = (uint2)(triangle.x, triangle.y);
                    to2[1] = (uint2)(triangle.z, triangle.x);
                    to2[2] = (uint2)(triangle.z, d);
                    r += 2;
                    continue;
                }
                vstore3(triangle, r, out);
                if (both)
                    vstore3((uint3)(triangle.x, triangle.z, d), r + 1, out);
                r += both ? 2 : 1;
                continue;
            }
#endif
            if (t == 0)
                pattern_primitives(f, collapsed, out + (size_t)3 * r, base);
            ++r;
        }
    }
    return;
#endif
