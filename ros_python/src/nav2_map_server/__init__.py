"""nav2_map_server for Python: Nav2's map files, map_server and map_saver_cli.

The same files as Nav2 Jazzy reads and writes (an image, ``.pgm`` by default,
and a ``.yaml`` beside it with ``image``, ``mode``, ``resolution``,
``origin``, ``negate``, ``occupied_thresh`` and ``free_thresh``), the same
node names, topics, services, parameters and log lines, so a map saved by
the real map_saver loads here and the other way round. Written from Nav2's
documentation and behaviour (``map_io``), in Python: images through our own
PGM reader and writer, other formats through Pillow.
"""
