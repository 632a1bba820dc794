"""What a study leaves: its tables, results.nc, figures, the paper's figure table, the comparison of two folders and
the reproduction report."""
