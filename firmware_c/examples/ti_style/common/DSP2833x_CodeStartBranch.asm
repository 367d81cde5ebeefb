; Branch to the C start-up code at reset (placeholder: the host build skips assembly).
