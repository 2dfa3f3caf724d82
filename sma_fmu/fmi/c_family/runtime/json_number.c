/* Decimal text -> double exactly as Python does it (see json_number.h).
 *
 * Reading: value = D * 10^E with D the significant digits. Small D and E take the exact
 * fast path (one correctly rounded multiplication or division by an exact power of ten);
 * otherwise an approximation is corrected ulp by ulp, comparing D * 10^E exactly with the
 * midpoints between neighbouring doubles in big-integer arithmetic. D keeps at most
 * MAX_DIGITS digits plus a sticky digit: a midpoint between doubles has at most 767
 * significant digits, so the comparisons come out as for the full text. */
#include "fp_contract.h"
#include "json_number.h"

#include <float.h>
#include <math.h>
#include <stdint.h>

#define MAX_DIGITS 800
#define BIG_LIMBS 200              /* 6400 bits: D 5^E 2^s stays below 5000 bits */
#define MANTISSA_TOP ((uint64_t)1 << 53)
#define MIN_EXPONENT (-1074)       /* of the last bit of a subnormal */
#define MAX_EXPONENT 971           /* of the last bit of DBL_MAX */

typedef struct Big {
    uint32_t limb[BIG_LIMBS];      /* little-endian base 2^32 */
    int size;
} Big;

static int big_mul_add(Big *big, uint32_t factor, uint32_t addend)
{
    uint64_t carry = addend;
    int i;
    for (i = 0; i < big->size; i++) {
        uint64_t product = (uint64_t)big->limb[i] * factor + carry;
        big->limb[i] = (uint32_t)product;
        carry = product >> 32;
    }
    if (carry != 0) {
        if (big->size == BIG_LIMBS) {
            return 1;
        }
        big->limb[big->size++] = (uint32_t)carry;
    }
    return 0;
}

static int big_set(Big *big, uint64_t value)
{
    big->size = 0;
    while (value != 0) {
        big->limb[big->size++] = (uint32_t)value;
        value >>= 32;
    }
    return 0;
}

static const uint32_t POWERS_OF_5[13] = {
    1u, 5u, 25u, 125u, 625u, 3125u, 15625u, 78125u, 390625u, 1953125u, 9765625u, 48828125u,
    244140625u};

static int big_mul_pow5(Big *big, int power)
{
    for (; power >= 13; power -= 13) {
        if (big_mul_add(big, 1220703125u, 0)) {   /* 5^13 */
            return 1;
        }
    }
    return big_mul_add(big, POWERS_OF_5[power], 0);
}

static int big_shift_left(Big *big, int bits)
{
    int words = bits / 32, rest = bits % 32, i;
    if (big->size == 0) {
        return 0;
    }
    if (big->size + words + 1 > BIG_LIMBS) {
        return 1;
    }
    big->limb[big->size] = 0;
    for (i = big->size; i >= 0; i--) {
        uint32_t high = big->limb[i] << rest;
        uint32_t low = (rest != 0 && i > 0) ? big->limb[i - 1] >> (32 - rest) : 0;
        big->limb[i + words] = high | low;
    }
    for (i = 0; i < words; i++) {
        big->limb[i] = 0;
    }
    big->size += words + 1;
    while (big->size > 0 && big->limb[big->size - 1] == 0) {
        big->size--;
    }
    return 0;
}

static int big_compare(const Big *a, const Big *b)
{
    int i;
    if (a->size != b->size) {
        return a->size < b->size ? -1 : 1;
    }
    for (i = a->size - 1; i >= 0; i--) {
        if (a->limb[i] != b->limb[i]) {
            return a->limb[i] < b->limb[i] ? -1 : 1;
        }
    }
    return 0;
}

/* The significant digits of a number and its decimal exponent: value = D * 10^exponent. */
typedef struct Decimal {
    char digits[MAX_DIGITS + 1];
    int count;
    long exponent;
} Decimal;

/* sign(D * 10^E - K * 2^f), or 2 when the integers outgrow Big (never for valid input). */
static int compare_midpoint(const Decimal *decimal, uint64_t K, int f)
{
    Big x, y;
    int i;
    long shift;
    x.size = 0;
    for (i = 0; i < decimal->count; i++) {
        if (big_mul_add(&x, 10, (uint32_t)(decimal->digits[i] - '0'))) {
            return 2;
        }
    }
    big_set(&y, K);
    if (decimal->exponent >= 0 ? big_mul_pow5(&x, (int)decimal->exponent)
                               : big_mul_pow5(&y, (int)-decimal->exponent)) {
        return 2;
    }
    shift = decimal->exponent - f;
    if (shift >= 0 ? big_shift_left(&x, (int)shift) : big_shift_left(&y, (int)-shift)) {
        return 2;
    }
    return big_compare(&x, &y);
}

/* The double nearest D * 10^E (D > 0), by correcting `guess` (finite, >= 0). */
static int nearest_double(const Decimal *decimal, double guess, double *out)
{
    uint64_t M;
    int e, step, c;
    if (guess == 0.0) {
        M = 0;
        e = MIN_EXPONENT;
    } else {
        int binary;
        double fraction = frexp(guess, &binary);
        M = (uint64_t)ldexp(fraction, 53);
        e = binary - 53;
        if (e < MIN_EXPONENT) {
            M = (uint64_t)ldexp(guess, -MIN_EXPONENT);
            e = MIN_EXPONENT;
        }
    }
    for (step = 0; step < 4096; step++) {
        c = compare_midpoint(decimal, 2 * M + 1, e - 1);          /* towards the next up */
        if (c == 2) {
            return 1;
        }
        if (c > 0 || (c == 0 && (M & 1))) {
            if (++M == MANTISSA_TOP) {
                M >>= 1;
                if (++e > MAX_EXPONENT) {
                    *out = HUGE_VAL;
                    return 0;
                }
            }
            continue;
        }
        if (M == 0) {
            break;
        }
        if (M == MANTISSA_TOP / 2 && e > MIN_EXPONENT) {
            c = compare_midpoint(decimal, 4 * M - 1, e - 2);      /* below a power of two */
        } else {
            c = compare_midpoint(decimal, 2 * M - 1, e - 1);
        }
        if (c == 2) {
            return 1;
        }
        if (c < 0 || (c == 0 && (M & 1))) {
            if (--M < MANTISSA_TOP / 2 && e > MIN_EXPONENT) {
                M = 2 * M + 1;
                e -= 1;
            }
            continue;
        }
        break;
    }
    if (step == 4096) {
        return 1;
    }
    *out = ldexp((double)M, e);
    return 0;
}

static const double EXACT_POWERS[23] = {
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
    1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

/* The double nearest D * 10^E, D > 0 (magnitude only). */
static int decimal_value(const Decimal *decimal, double *out)
{
    uint64_t leading = 0;
    long exponent = decimal->exponent, scale;
    int i, used = decimal->count < 19 ? decimal->count : 19;
    long magnitude = decimal->count - 1 + exponent;   /* value in [10^m, 10^(m+1)) */
    double guess;
    if (magnitude < -325) {
        *out = 0.0;
        return 0;
    }
    if (magnitude > 309) {
        *out = HUGE_VAL;
        return 0;
    }
    for (i = 0; i < used; i++) {
        leading = leading * 10 + (uint64_t)(decimal->digits[i] - '0');
    }
    if (decimal->count <= 19 && leading < MANTISSA_TOP && exponent >= -22 && exponent <= 22) {
        *out = exponent >= 0 ? (double)leading * EXACT_POWERS[exponent]
                             : (double)leading / EXACT_POWERS[-exponent];
        return 0;
    }
    guess = (double)leading;
    for (scale = exponent + (decimal->count - used); scale > 22; scale -= 22) {
        guess *= 1e22;
    }
    for (; scale < -22; scale += 22) {
        guess /= 1e22;
    }
    guess = scale >= 0 ? guess * EXACT_POWERS[scale] : guess / EXACT_POWERS[-scale];
    if (!(guess <= DBL_MAX)) {
        guess = DBL_MAX;
    }
    return nearest_double(decimal, guess, out);
}

int json_number_value(const char *text, size_t length, double *out)
{
    static Decimal zero_decimal;
    Decimal decimal = zero_decimal;
    size_t at = 0;
    int negative = 0, fraction = 0, sticky = 0, value_written = 0;
    long exponent = 0, dropped = 0;
    double magnitude;
    if (at < length && text[at] == '-') {
        negative = 1;
        at++;
    }
    if (at >= length || text[at] < '0' || text[at] > '9' || (text[at] == '0' && at + 1 < length
        && text[at + 1] >= '0' && text[at + 1] <= '9')) {
        return 1;
    }
    for (; at < length; at++) {
        char c = text[at];
        if (c == '.' && !fraction) {
            fraction = 1;
            if (at + 1 >= length || text[at + 1] < '0' || text[at + 1] > '9') {
                return 1;
            }
            continue;
        }
        if (c < '0' || c > '9') {
            break;
        }
        value_written = 1;
        if (decimal.count == 0 && c == '0') {           /* leading zeros */
            exponent -= fraction;
            continue;
        }
        if (decimal.count < MAX_DIGITS) {
            decimal.digits[decimal.count++] = c;
            exponent -= fraction;
        } else {
            sticky |= c != '0';
            dropped += !fraction;
        }
    }
    if (!value_written) {
        return 1;
    }
    if (at < length) {
        long written = 0;
        int exponent_negative = 0, exponent_digits = 0;
        if (text[at] != 'e' && text[at] != 'E') {
            return 1;
        }
        at++;
        if (at < length && (text[at] == '+' || text[at] == '-')) {
            exponent_negative = text[at] == '-';
            at++;
        }
        for (; at < length && text[at] >= '0' && text[at] <= '9'; at++, exponent_digits++) {
            if (written < 100000000L) {
                written = written * 10 + (text[at] - '0');
            }
        }
        if (exponent_digits == 0 || at != length) {
            return 1;
        }
        exponent += exponent_negative ? -written : written;
    }
    exponent += dropped;
    if (sticky) {
        decimal.digits[decimal.count++] = '1';
        exponent -= 1;
    }
    while (decimal.count > 0 && decimal.digits[decimal.count - 1] == '0') {
        decimal.count--;
        exponent++;
    }
    decimal.exponent = exponent;
    if (decimal.count == 0) {
        magnitude = 0.0;
    } else if (decimal_value(&decimal, &magnitude)) {
        return 1;
    }
    *out = negative ? -magnitude : magnitude;
    return 0;
}
