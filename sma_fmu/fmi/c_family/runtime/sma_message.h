/* Error messages of the C runtime: the text of Python's ValueError.
 *
 * A function that can fail returns int (0 ok, nonzero error) and fills a SmaMessage.
 * Only the runtime's own literal strings are ever formats: any text that came from
 * outside (a String parameter, a mode name) is passed as a "%s" argument. */
#ifndef SMA_MESSAGE_H
#define SMA_MESSAGE_H

typedef struct {
    char text[512];
} SmaMessage;

#if defined(__GNUC__) && defined(__MINGW32__)
#define SMA_PRINTF_FORMAT(a, b) __attribute__((format(gnu_printf, a, b)))
#elif defined(__GNUC__)
#define SMA_PRINTF_FORMAT(a, b) __attribute__((format(printf, a, b)))
#else
#define SMA_PRINTF_FORMAT(a, b)
#endif

/* A small function defined in a header, so a step's passing checks cost no call (MSVC's C
 * mode spells C99's inline __inline). */
#if defined(_MSC_VER) && !defined(__cplusplus)
#define SMA_INLINE static __inline
#else
#define SMA_INLINE static inline
#endif

/* Formats into message->text with vsnprintf (truncated to fit); a NULL message is allowed
 * and ignored. Returns 1, so `return sma_message_set(...)` reports an error. */
int sma_message_set(SmaMessage *message, const char *format, ...) SMA_PRINTF_FORMAT(2, 3);

#endif
