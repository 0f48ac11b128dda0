"""Plumbing that every other folder may use, and that uses nothing of the package.

- ``errors``   the package's errors, each a ``PGAELiteError`` (the command line prints them)
- ``atomic_files``  writes that never leave half a file or half a folder (and a dangling link said as such)
- ``folder_lock``   one training run at a time in a folder; a read-only folder is read without a lock
- ``storage``  the cache folder, the device, saved torch files and their one set of load checks, config digests
- ``checks``   argument checks shared by the public functions (seeds, devices, numbers, input and output folders)
"""
