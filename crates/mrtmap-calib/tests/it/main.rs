mod real;
mod synthetic;
