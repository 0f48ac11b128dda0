"""Handing the book out as a course (not in the paper).

- ``student_edition``  the book and its notebooks without the exercises' solutions, from the same sources
"""
