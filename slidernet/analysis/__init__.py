"""From records to answers: the result dataset and its statistics, the theory, pictures of networks."""
