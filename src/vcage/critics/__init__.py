"""Critics judge a subtask's outcome; the oracle audits every one from simulator state."""
