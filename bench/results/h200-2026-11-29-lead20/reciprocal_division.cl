/* kernels/common.h markstein_quotient against the correctly rounded a / b (bench/reciprocal_division.py):
 * a and b in [1, 2), their significands a_first + .. and b_first + .. (23 bits each).  Work-item
 * (i, j) takes b's significand b_first + j and a_per_item dividends from a_first + i a_per_item,
 * counts the pairs whose quotients differ in any bit and keeps the first few of them. */
#include "common.h"

__kernel void markstein_against_division(uint a_first, uint a_per_item, uint b_first,
                                         __global uint *mismatches, __global uint2 *examples, uint max_examples)
{
    float b = as_float(0x3f800000u | (b_first + (uint)get_global_id(1)));
    float r = 1.0f / b;
    uint from = a_first + (uint)get_global_id(0) * a_per_item, bad = 0;
    for (uint k = 0; k < a_per_item; ++k) {
        float a = as_float(0x3f800000u | (from + k));
        if (as_uint(markstein_quotient(a, b, r)) != as_uint(a / b)) {
            uint slot = atomic_inc(&mismatches[1]);
            if (slot < max_examples)
                examples[slot] = (uint2)(as_uint(a), as_uint(b));
            ++bad;
        }
    }
    if (bad)
        atomic_add(&mismatches[0], bad);
}
