"""Several runs side by side: labels and differences, compare, leaderboard and findings."""
