"""Figures: results in, matplotlib axes out (no plt.show()).

Submodules by step of the design loop; matplotlib is imported only here.
"""
