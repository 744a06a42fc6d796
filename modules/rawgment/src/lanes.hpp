// This file is part of cv::rawgment, licensed under the Apache License 2.0 (see LICENSE).
// The vector types of the hot kernels: GCC's vector extensions where the compiler has them, and on the
// portable path (RAWGMENT_PORTABLE_LANES, for compilers without them) an array of lanes with the same
// semantics, operation by operation, so the kernels are one source and give the same bits either way.
//
// The kernels write a vector type as RAWGMENT_VECTOR(element, bytes), convert lanes with convertLanes<To>()
// (GCC's __builtin_convertvector) and choose lanes with selectLanes(mask, a, b) (GCC's vector `?:`, which a
// class cannot overload). A C-style cast between vector types of one size reinterprets the bits in both.
#ifndef OPENCV_RAWGMENT_SRC_LANES_HPP
#define OPENCV_RAWGMENT_SRC_LANES_HPP

#include <cstdint>
#include <cstring>
#include <type_traits>

#if !defined(RAWGMENT_PORTABLE_LANES) && !(defined(__GNUC__) || defined(__clang__))
#define RAWGMENT_PORTABLE_LANES 1
#endif

#if defined(__GNUC__) || defined(__clang__)
#define RAWGMENT_ALWAYS_INLINE inline __attribute__((always_inline))
#else
#define RAWGMENT_ALWAYS_INLINE inline
#endif

namespace cv {
namespace rawgment {
namespace detail {

#if defined(RAWGMENT_PORTABLE_LANES)

//! The signed integer of a lane's size: the lanes of a comparison's mask (-1 true, 0 false).
template <typename T>
using MaskLane = std::make_signed_t<std::conditional_t<
    sizeof(T) == 8, int64_t,
    std::conditional_t<sizeof(T) == 4, int32_t, std::conditional_t<sizeof(T) == 2, int16_t, int8_t>>>>;

/** N lanes of T, an aggregate (so `V v = {}` and `V{a, b, ...}` work as for GCC vectors). Integer lanes
 * wrap on overflow as GCC's vector lanes do: the arithmetic runs on the unsigned type. */
template <typename T, int N> struct LaneArray
{
    T lane[N];

    T& operator[](int i) { return lane[i]; }
    const T& operator[](int i) const { return lane[i]; }

    //! A C-style cast to another vector type of the same size: the same bits.
    template <typename U, int M> explicit operator LaneArray<U, M>() const
    {
        static_assert(sizeof(U) * M == sizeof(T) * N, "a vector cast keeps the size");
        LaneArray<U, M> r;
        std::memcpy(&r, this, sizeof(r));
        return r;
    }
};

template <typename T> struct IsLaneArray : std::false_type
{
};
template <typename T, int N> struct IsLaneArray<LaneArray<T, N>> : std::true_type
{
};

template <typename T> RAWGMENT_ALWAYS_INLINE T wrapAdd(T a, T b)
{
    if constexpr (std::is_integral_v<T>)
        return static_cast<T>(static_cast<std::make_unsigned_t<T>>(a) +
                              static_cast<std::make_unsigned_t<T>>(b));
    else
        return a + b;
}
template <typename T> RAWGMENT_ALWAYS_INLINE T wrapSub(T a, T b)
{
    if constexpr (std::is_integral_v<T>)
        return static_cast<T>(static_cast<std::make_unsigned_t<T>>(a) -
                              static_cast<std::make_unsigned_t<T>>(b));
    else
        return a - b;
}
template <typename T> RAWGMENT_ALWAYS_INLINE T wrapMul(T a, T b)
{
    if constexpr (std::is_integral_v<T>)
        return static_cast<T>(static_cast<std::make_unsigned_t<T>>(a) *
                              static_cast<std::make_unsigned_t<T>>(b));
    else
        return a * b;
}
template <typename T> RAWGMENT_ALWAYS_INLINE T shiftLeft(T a, int s)
{
    return static_cast<T>(static_cast<std::make_unsigned_t<T>>(a) << s);
}

//! A scalar in every lane: how GCC's vector extensions widen a scalar operand of a vector operator.
template <typename T, int N, typename S> RAWGMENT_ALWAYS_INLINE LaneArray<T, N> broadcastLanes(S s)
{
    LaneArray<T, N> r;
    for (int i = 0; i < N; ++i)
        r.lane[i] = static_cast<T>(s);
    return r;
}

#define RAWGMENT_LANES_BINARY(op, expr)                                                                      \
    template <typename T, int N>                                                                             \
    RAWGMENT_ALWAYS_INLINE LaneArray<T, N> operator op(const LaneArray<T, N>& a, const LaneArray<T, N>& b)   \
    {                                                                                                        \
        LaneArray<T, N> r;                                                                                   \
        for (int i = 0; i < N; ++i) {                                                                        \
            const T x = a.lane[i], y = b.lane[i];                                                            \
            r.lane[i] = static_cast<T>(expr);                                                                \
        }                                                                                                    \
        return r;                                                                                            \
    }                                                                                                        \
    template <typename T, int N, typename S, std::enable_if_t<std::is_arithmetic_v<S>, int> = 0>             \
    RAWGMENT_ALWAYS_INLINE LaneArray<T, N> operator op(const LaneArray<T, N>& a, S s)                        \
    {                                                                                                        \
        return a op broadcastLanes<T, N>(s);                                                                 \
    }                                                                                                        \
    template <typename T, int N, typename S, std::enable_if_t<std::is_arithmetic_v<S>, int> = 0>             \
    RAWGMENT_ALWAYS_INLINE LaneArray<T, N> operator op(S s, const LaneArray<T, N>& b)                        \
    {                                                                                                        \
        return broadcastLanes<T, N>(s) op b;                                                                 \
    }                                                                                                        \
    template <typename T, int N, typename S>                                                                 \
    RAWGMENT_ALWAYS_INLINE LaneArray<T, N>& operator op##=(LaneArray<T, N>& a, const S& b)                   \
    {                                                                                                        \
        a = a op b;                                                                                          \
        return a;                                                                                            \
    }

RAWGMENT_LANES_BINARY(+, wrapAdd(x, y))
RAWGMENT_LANES_BINARY(-, wrapSub(x, y))
RAWGMENT_LANES_BINARY(*, wrapMul(x, y))
RAWGMENT_LANES_BINARY(/, x / y)
RAWGMENT_LANES_BINARY(&, x& y)
RAWGMENT_LANES_BINARY(|, x | y)
RAWGMENT_LANES_BINARY(^, x ^ y)
RAWGMENT_LANES_BINARY(<<, shiftLeft(x, static_cast<int>(y)))
RAWGMENT_LANES_BINARY(>>, x >> y)
#undef RAWGMENT_LANES_BINARY

#define RAWGMENT_LANES_COMPARE(op)                                                                           \
    template <typename T, int N>                                                                             \
    RAWGMENT_ALWAYS_INLINE LaneArray<MaskLane<T>, N> operator op(const LaneArray<T, N>& a,                   \
                                                                 const LaneArray<T, N>& b)                   \
    {                                                                                                        \
        LaneArray<MaskLane<T>, N> r;                                                                         \
        for (int i = 0; i < N; ++i)                                                                          \
            r.lane[i] = a.lane[i] op b.lane[i] ? MaskLane<T>(-1) : MaskLane<T>(0);                           \
        return r;                                                                                            \
    }                                                                                                        \
    template <typename T, int N, typename S, std::enable_if_t<std::is_arithmetic_v<S>, int> = 0>             \
    RAWGMENT_ALWAYS_INLINE LaneArray<MaskLane<T>, N> operator op(const LaneArray<T, N>& a, S s)              \
    {                                                                                                        \
        return a op broadcastLanes<T, N>(s);                                                                 \
    }                                                                                                        \
    template <typename T, int N, typename S, std::enable_if_t<std::is_arithmetic_v<S>, int> = 0>             \
    RAWGMENT_ALWAYS_INLINE LaneArray<MaskLane<T>, N> operator op(S s, const LaneArray<T, N>& b)              \
    {                                                                                                        \
        return broadcastLanes<T, N>(s) op b;                                                                 \
    }

RAWGMENT_LANES_COMPARE(<)
RAWGMENT_LANES_COMPARE(>)
RAWGMENT_LANES_COMPARE(<=)
RAWGMENT_LANES_COMPARE(>=)
RAWGMENT_LANES_COMPARE(==)
RAWGMENT_LANES_COMPARE(!=)
#undef RAWGMENT_LANES_COMPARE

template <typename T, int N> RAWGMENT_ALWAYS_INLINE LaneArray<T, N> operator-(const LaneArray<T, N>& a)
{
    return T(0) - a;
}
template <typename T, int N> RAWGMENT_ALWAYS_INLINE LaneArray<T, N> operator~(const LaneArray<T, N>& a)
{
    LaneArray<T, N> r;
    for (int i = 0; i < N; ++i)
        r.lane[i] = static_cast<T>(~a.lane[i]);
    return r;
}

} // namespace detail

//! GCC's __builtin_convertvector: each lane converted as a scalar is.
template <typename To, typename T, int N>
RAWGMENT_ALWAYS_INLINE To convertLanes(const detail::LaneArray<T, N>& v)
{
    To r;
    for (int i = 0; i < N; ++i)
        r.lane[i] = static_cast<std::remove_reference_t<decltype(r.lane[0])>>(v.lane[i]);
    return r;
}

//! GCC's vector `mask ? a : b`: lane i of a where mask lane i is non-zero, else of b.
template <typename M, typename V> RAWGMENT_ALWAYS_INLINE V selectLanes(const M& mask, const V& a, const V& b)
{
    V r;
    for (int i = 0; i < static_cast<int>(sizeof(V) / sizeof(a.lane[0])); ++i)
        r.lane[i] = mask.lane[i] ? a.lane[i] : b.lane[i];
    return r;
}

#define RAWGMENT_VECTOR(T, bytes) ::cv::rawgment::detail::LaneArray<T, static_cast<int>((bytes) / sizeof(T))>

#else

} // namespace detail

#define RAWGMENT_VECTOR(T, bytes) T __attribute__((vector_size(bytes)))

template <typename To, typename V> RAWGMENT_ALWAYS_INLINE To convertLanes(V v)
{
    return __builtin_convertvector(v, To);
}

template <typename M, typename V> RAWGMENT_ALWAYS_INLINE V selectLanes(M mask, V a, V b)
{
    return mask ? a : b;
}

#endif

//! The index of the lowest set bit of a non-zero word (GCC's __builtin_ctz).
RAWGMENT_ALWAYS_INLINE int lowestSetBit(unsigned bits)
{
#if defined(__GNUC__) || defined(__clang__)
    return __builtin_ctz(bits);
#else
    int i = 0;
    while (!(bits & 1u)) {
        bits >>= 1;
        ++i;
    }
    return i;
#endif
}

} // namespace rawgment
} // namespace cv

#endif // OPENCV_RAWGMENT_SRC_LANES_HPP
