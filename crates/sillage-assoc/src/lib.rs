//! Neighbour search (k-d tree with a brute-force reference), mutual nearest neighbours, assignment.
