"""Core building blocks on arrays, shared by every codec: N-step phase, stair phases,
capture scaling and validity, fringe-set measurement, fringe regions, fringe-order
resolution and the decode result.

Nothing here knows a spec or a file; the codecs (:mod:`bistair.codecs`) build on it.
"""
