"""Plumbing that every other folder may use, and that uses nothing of the package.

- ``errors``   the package's errors, each a ``PGAELiteError`` (the command line prints them)
- ``storage``  the cache folder, the device, atomic writes, checkpoint files, folder locks, config digests
- ``checks``   argument checks shared by the public functions (seeds, devices, numbers)
"""
