// Types of scripts/code-health.mjs for the vitest that runs it (tests/code-health.test.ts).
export declare const MAX_FUNCTION_LINES: number;
export declare const SRC: string;
export interface FunctionLength {
  name: string;
  line: number;
  lines: number;
}
export declare function sourceFiles(dir?: string): string[];
export declare function functionLengths(text: string, fileName?: string): FunctionLength[];
export declare function domCalls(text: string, fileName?: string): { calls: number; replaceChildren: number };
export declare function importsOf(text: string, fileName: string): string[];
export declare function importCycles(files?: string[]): string[][];
export declare function measure(files?: string[]): {
  functions: (FunctionLength & { file: string })[];
  calls: number;
  filesWithCalls: number;
  replaceChildren: number;
};
