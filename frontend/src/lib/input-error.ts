/** Input the form cannot even turn into a request (JSON that does not parse), located like a 422 problem. */
export class InputError extends Error {
  constructor(
    readonly path: string,
    message: string,
  ) {
    super(message);
    this.name = "InputError";
  }
}
