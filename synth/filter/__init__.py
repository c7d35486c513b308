"""The safety logic filter (the lab's second method): the ``.filter`` language, coherence checks P1–P4, algebraic synthesis, Structured Text, closed-loop verification."""
