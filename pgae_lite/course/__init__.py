"""Handing the book out as a course (not in the paper).

- ``student_edition``  the book and its notebooks without the exercises' solutions, from the same sources
- ``prepare``          a class's cache, once: every chapter executed, so that no student waits for a training
- ``assign``           the problem sets and labs (``course/``) as the notebooks to hand out and their autograders
- ``grade``            a folder of submitted notebooks graded offline into a score report, whatever they hold
- ``syllabus``         what the course holds, read from its masters: questions, points, checks, rubrics
- ``selfgrade``        the course through its own grader: solutions full marks, handouts zero, wrong parts diagnosed
- ``cli``              ``python -m pgae_lite course prepare | assign | grade``
- ``labs``             the labs: each changes one component of PGAE within a class period (a folder)
"""
